"""A build is a function of its inputs (issue 35 item 1), as a property.

Random sequences of 3-5 edits to the demo case (resample, links, export.q,
export formats, fit keys, material), each followed by a rebuild into the same
folder (unchanged stages loaded from it, the rest recomputed on what was
loaded), then a fresh build of the final case: the two folders hold the same
files, byte for byte, the manifest included.  Only the run log
(``run.log.json``: each stage's status, ran or skipped, and its seconds)
records how the folder was reached, and it is the one file left out.

Coarse settings keep a build to about a second: the property is about caching, not resolution.

Every run tries the three written examples below, which between them make every kind of edit (each of the nine
keys, a block removed and put back), upstream and downstream of one another, then :data:`DRAWN_EXAMPLES` drawn
ones (new orders and values each run; Hypothesis's database replays a failure first).  ``make study-property``
draws :data:`STUDY_EXAMPLES` (the count ``make test`` drew before the suite had to fit in 15 minutes).
"""

from __future__ import annotations

import copy
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, Phase, example, given, settings
from hypothesis import strategies as st

from softdesign.pipeline.api import build_through
from tests.helpers.folders import snapshot
from tests.helpers.paths import REPO

#: The demo case at coarse settings (1 mm samples and rings, 3 mm x 12 fit knots, 40 vertices around).
BASE: dict[str, Any] = {
    "name": "demo",
    "units": "mm",
    "final": {"centerline": str(REPO / "data" / "demo" / "centerline.vtp"),
              "surface": str(REPO / "data" / "demo" / "surface.stl"), "path": 0},
    "initial": {"kind": "straight"},
    "resample": {"spacing_mm": 1.0, "smoothing_mm": 0.05, "end_straight_mm": 0.0},
    "frames": "rmf",
    "blend": "linear",
    "links": {"count": 4},
    "fit": {"knot_spacing_mm": 3.0, "angular_intervals": 12, "smoothing": 1.0e-5},
    "export": {"q": [0, 1], "formats": ["stl"], "spacing_mm": 1.0, "angular_count": 40},
}

#: Drawn examples in `make test` (each 3-5 rebuilds and a fresh build, about a second each), and in
#: `make study-property` (which sets SOFTDESIGN_PROPERTY_EXAMPLES).  Three, not five: the written examples make
#: every kind of edit each run; the drawn ones add orders and pairings of edits, different in every run (CI's
#: included), so that they add up over runs, and a failure is replayed first (about 6 s each on 2 busy cores).
DRAWN_EXAMPLES, STUDY_EXAMPLES = 3, 20
#: The most drawn examples the variable may ask for (about 20 minutes).
MAX_EXAMPLES = 200


def drawn_examples() -> int:
    """SOFTDESIGN_PROPERTY_EXAMPLES (1 to MAX_EXAMPLES) when set, else DRAWN_EXAMPLES."""
    text = os.environ.get("SOFTDESIGN_PROPERTY_EXAMPLES", str(DRAWN_EXAMPLES))
    if not (text.isdigit() and 1 <= int(text) <= MAX_EXAMPLES):
        raise pytest.UsageError(f"SOFTDESIGN_PROPERTY_EXAMPLES must be a whole number from 1 to {MAX_EXAMPLES}, "
                                f"got {text!r}: unset it for make test's {DRAWN_EXAMPLES}")
    return int(text)


#: One edit: (where, value); "material" replaces the block (None removes it), the others set one key.
EDITS = st.one_of(
    st.tuples(st.just("resample.spacing_mm"), st.sampled_from([1.0, 1.25])),
    st.tuples(st.just("resample.smoothing_mm"), st.sampled_from([0.05, 0.1])),
    st.tuples(st.just("links"), st.sampled_from([{"count": 4}, {"count": 3}, {"length_mm": 25.0},
                                                 {"breaks": [0.0, 0.4, 1.0]}])),
    st.tuples(st.just("export.q"), st.sampled_from([[0, 1], [0, 0.5, 1], [0.25, 1]])),
    st.tuples(st.just("export.formats"), st.sampled_from([["stl"], ["stl", "ply"], ["obj"], ["vtp"]])),
    st.tuples(st.just("fit.knot_spacing_mm"), st.sampled_from([3.0, 4.0])),
    st.tuples(st.just("fit.angular_intervals"), st.sampled_from([12, 16])),
    st.tuples(st.just("fit.smoothing"), st.sampled_from([1.0e-5, 3.0e-5])),
    st.tuples(st.just("material"), st.sampled_from([None, {"name": "ecoflex-00-30"}, {"name": "dragon-skin-30"}])),
)


def apply(case: dict[str, Any], where: str, value: Any) -> None:
    """Set the dotted key ``where`` of ``case`` to ``value`` (a top-level None removes the key)."""
    *parents, key = where.split(".")
    node = case
    for part in parents:
        node = node[part]
    if value is None:
        node.pop(key, None)
    else:
        node[key] = copy.deepcopy(value)


def build(case: dict[str, Any], case_file: Path, out: Path) -> None:
    case_file.write_text(yaml.safe_dump(case, sort_keys=False), encoding="utf-8")
    build_through(case_file, out)


def without_run_record(manifest_file: Path) -> dict[str, Any]:
    """The manifest: the run's stage times and statuses are in the run log, never here."""
    manifest = json.loads(manifest_file.read_text(encoding="utf-8"))
    assert "timing_s" not in manifest and not any("status" in stage for stage in manifest["stages"])
    return manifest


@pytest.fixture(scope="module")
def first_build(tmp_path_factory) -> Path:
    """The base case built once; each example starts from a copy of it."""
    root = tmp_path_factory.mktemp("first")
    build(BASE, root / "case.yaml", root / "build")
    return root / "build"


@pytest.mark.slow
@settings(max_examples=drawn_examples(), deadline=None, phases=(Phase.explicit, Phase.reuse, Phase.generate),
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(edits=st.lists(EDITS, min_size=3, max_size=5))
@example(edits=[("resample.spacing_mm", 1.25), ("fit.knot_spacing_mm", 4.0), ("export.formats", ["stl", "ply"])])
@example(edits=[("export.q", [0, 0.5, 1]), ("links", {"count": 3}), ("resample.smoothing_mm", 0.1),
                ("fit.angular_intervals", 16)])
@example(edits=[("material", None), ("fit.smoothing", 3.0e-5), ("links", {"breaks": [0.0, 0.4, 1.0]}),
                ("material", {"name": "dragon-skin-30"})])
def test_rebuilds_after_any_edits_give_a_fresh_builds_bytes(first_build, edits):
    # no shrinking phase: each step is a build; a failure prints its edits as drawn
    with tempfile.TemporaryDirectory(prefix="incremental-") as scratch:
        root = Path(scratch)
        incremental, fresh = root / "incremental", root / "fresh"
        shutil.copytree(first_build, incremental)
        case = copy.deepcopy(BASE)
        for where, value in edits:
            apply(case, where, value)
            build(case, root / "case.yaml", incremental)
        build(case, root / "case.yaml", fresh)
        one, two = snapshot(incremental), snapshot(fresh)
        assert one.keys() == two.keys()
        differing = sorted(name for name in one if one[name] != two[name] and name != "run.log.json")
        assert differing == [], f"after {edits}: {differing}"
        assert without_run_record(incremental / "manifest.json") == without_run_record(fresh / "manifest.json")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["kinematics", "fit", "export", "feasibility"])
def test_a_stage_recomputed_on_results_loaded_from_the_folder_writes_the_kept_bytes(first_build, name, tmp_path):
    """The issue's other half: every stage before ``name`` loaded from the build folder, ``name`` computed again."""
    from softdesign.config import load_case
    from softdesign.pipeline.stage_order import STAGES
    from softdesign.pipeline.store import Staging

    case_file = tmp_path / "case.yaml"
    case_file.write_text(yaml.safe_dump(BASE, sort_keys=False), encoding="utf-8")
    case = load_case(case_file)
    results: dict[str, Any] = {}
    for stage in STAGES:
        if stage.name == name:
            break
        results[stage.name] = stage.load(first_build, results)
    stage = next(s for s in STAGES if s.name == name)
    kept = json.loads((first_build / name / "stage.json").read_text(encoding="utf-8"))["outputs"]
    with Staging(tmp_path / "again") as staging:
        stage.write(stage.compute(case, results), staging)
        assert staging.written == kept
