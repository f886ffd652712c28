"""CI's mesh guard: a fresh `make cohort` of the sample cohort checked against tests/golden (made by `make golden`).

A failure here means a change moved a mesh, a link transform or a fit
metric of a sample case.  If the change is intended, run `make golden` and
commit tests/golden with it; otherwise the table printed by `softdesign
check` names what moved and by how much.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.cohort import cohort_cases
from softdesign.pipeline.store import sha256_file
from softdesign.regression import GOLDEN, CheckOptions, mesh_names
from tests.helpers.paths import REPO
from tests.helpers.sample_cohort import BROKEN, sample_cohort

from .test_cohort import MAKE

#: The sample cohort built afresh: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

COHORT = REPO / "configs" / "cohort"
REFERENCES = REPO / "tests" / "golden"
CASES = [p.stem for p in cohort_cases(COHORT)]
#: Relative change of a full-resolution mesh's volume and area (the manifest's figures), as check's default.
RTOL = CheckOptions().rtol
#: The references stay small: decimated meshes, JSON, no full-resolution meshes.
MAX_GOLDEN_BYTES = 1_500_000
#: What `make golden` promises about every stored mesh's own error, mm (pipelines/golden.py MAX_ERROR_MM).
MAX_DECIMATION_MM = 0.05
REGENERATE = "if the change is intended, run `make golden` and commit tests/golden"


@pytest.fixture(scope="module")
def fresh_cohort(tmp_path_factory) -> Path:
    """The sample cohort built by `make -j2 cohort` into a temporary folder: the run's shared build of copies of
    configs/cohort (the same bytes, inputs in the same layout; tests/helpers/sample_cohort.py), made once for this
    file and tests/e2e/test_snakemake.py, beside a broken case that only the Snakemake test reads (make exits 2
    for it, so the sample cases' success is read from their rows: the summary test below)."""
    if MAKE is None:
        pytest.skip("GNU make not found: the sample cohort is built by `make cohort`")
    cohort = sample_cohort(tmp_path_factory)
    for name in CASES:
        assert (cohort.cases / f"{name}.yaml").read_bytes() == (COHORT / f"{name}.yaml").read_bytes()
    assert (cohort.build / "cohort-summary.csv").is_file(), f"make cohort failed:\n{cohort.output}"
    return cohort.build


def golden(name: str) -> dict:
    return json.loads((REFERENCES / name / GOLDEN).read_text(encoding="utf-8"))


def test_every_sample_case_has_references_and_nothing_else_does():
    stored = sorted(p.parent.name for p in REFERENCES.glob(f"*/{GOLDEN}"))
    assert stored == CASES, f"tests/golden holds {stored}, configs/cohort has {CASES}: {REGENERATE}"


def test_references_are_small():
    size = sum(p.stat().st_size for p in REFERENCES.rglob("*") if p.is_file())
    assert size < MAX_GOLDEN_BYTES, f"tests/golden is {size} bytes"


@pytest.mark.parametrize("name", CASES)
def test_references_were_made_from_the_current_case_file_and_inputs(name):
    record = golden(name)
    case_file = COHORT / f"{name}.yaml"
    assert record["case"]["sha256"] == sha256_file(case_file), f"{case_file} changed since the references: {REGENERATE}"
    for entry in record["inputs"]:
        path = COHORT / entry["path"]
        assert entry["sha256"] == sha256_file(path), f"{path} changed since the references: {REGENERATE}"
    assert {"softdesign", "numpy", "scipy", "manifold3d", "vtk"} <= set(record["versions"])


@pytest.mark.parametrize("name", CASES)
def test_every_stored_mesh_has_its_decimation_error(name):
    meshes = golden(name)["meshes"]
    assert set(meshes) == mesh_names(REFERENCES / name)
    for mesh, entry in meshes.items():
        assert 0.0 <= entry["distance_max_mm"] <= MAX_DECIMATION_MM, mesh
        assert {"volume_rel_change", "area_rel_change"} <= set(entry), mesh


def test_summary_of_the_fresh_cohort_has_one_ok_row_per_case(fresh_cohort):
    with (fresh_cohort / "cohort-summary.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    # the shared build's broken case (tests/helpers/sample_cohort.py) fails its own row only
    assert [(row["case"], row["status"]) for row in rows] == sorted([(name, "ok") for name in CASES]
                                                                    + [(BROKEN, "failed")])


@pytest.mark.parametrize("name", CASES)
def test_fresh_build_passes_check_against_its_references(fresh_cohort, name):
    result = CliRunner().invoke(app, ["check", str(fresh_cohort / name), "--reference", str(REFERENCES / name)])
    assert result.exit_code == 0, f"{name} moved from tests/golden ({REGENERATE}):\n{result.output}"
    assert "warning:" not in result.output, f"{name}: check takes the references for another case:\n{result.output}"


@pytest.mark.parametrize("name", CASES)
def test_full_resolution_volume_and_area_match_the_references(fresh_cohort, name):
    """The manifest's figures of the full meshes: no decimation allowance here."""
    figures = {}
    for side in (fresh_cohort / name, REFERENCES / name):
        manifest = json.loads((side / "manifest.json").read_text(encoding="utf-8"))
        figures[side] = {o["path"]: o for o in manifest["outputs"] if "volume_mm3" in o}
    ours, theirs = figures.values()
    assert set(ours) == set(theirs)
    for path in ours:
        for key in ("volume_mm3", "area_mm2"):
            change = ours[path][key] / theirs[path][key] - 1.0
            assert abs(change) <= RTOL, f"{name} {path} {key}: {change:+.2e} relative, tolerance {RTOL} ({REGENERATE})"
        assert ours[path]["watertight"] == theirs[path]["watertight"] is True
