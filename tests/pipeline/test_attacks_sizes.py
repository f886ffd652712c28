"""Sizes that follow from a spacing and the vessel: refused right after ingest, within the memory budget, fast.

Each attack rebuilds over a prior build in a child limited to the memory
budget (RLIMIT_AS = softdesign.limits.MEMORY_BUDGET_BYTES) and a timeout; it
must exit 2 naming the key, the value, the limit and the fix, and leave the
prior build folder byte for byte as it was.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from softdesign.limits import MAX_CURVE_SAMPLES, MAX_EXPORT_VERTICES, MAX_FIT_COEFFICIENTS, MAX_LINKS, MAX_MESH_VERTICES
from tests.helpers.attacks import BUILD_TIMEOUT_S, assert_refused, demo_case, run_limited
from tests.helpers.folders import snapshot

#: How far the vertex estimate of softdesign.pipeline.bounds may fall short of a mesh's vertices (caps, joint rings).
ESTIMATE_RTOL = 0.01


def demo_length_mm(build: Path) -> float:
    import json

    return json.loads((build / "blend" / "summary.json").read_text())["final_path"]["length_mm"]


@pytest.mark.parametrize(
    ("sections", "needles"),
    [
        ({"resample": {"spacing_mm": 1e-6}},
         ["resample.spacing_mm: 1e-06 mm", f"limit of {MAX_CURVE_SAMPLES}", "use resample.spacing_mm >="]),
        ({"links": {"count": None, "length_mm": 1e-6}},
         ["links.length_mm: 1e-06 mm", f"limit of {MAX_LINKS}", "use links.length_mm >="]),
        ({"fit": {"knot_spacing_mm": 1e-4}},
         ["fit.knot_spacing_mm: 0.0001 mm", f"limit of {MAX_FIT_COEFFICIENTS}", "use fit.knot_spacing_mm >="]),
        ({"export": {"q": [0, 1], "spacing_mm": 1e-6}},
         ["export.spacing_mm: 1e-06 mm", f"limit of {MAX_MESH_VERTICES}", "use export.spacing_mm >="]),
        ({"export": {"q": None, "frames": 1001, "spacing_mm": 0.1, "angular_count": 64}},
         ["export.frames: 1001 meshes", f"limit of {MAX_EXPORT_VERTICES}", "export at most"]),
    ],
    ids=["resample-spacing", "links-length", "knot-spacing", "export-spacing", "frames"],
)
def test_a_spacing_the_vessel_cannot_afford_is_refused_before_the_stages_run(tmp_path, out, sections, needles):
    before = snapshot(out)
    case = demo_case(tmp_path, **sections)
    result = run_limited("build", str(case), "--out", str(out))
    assert_refused(result, str(case), *needles, "2 GiB")
    assert "blend: running" not in result.stderr  # refused after ingest, before any other stage
    assert snapshot(out) == before


def test_the_suggested_spacing_is_within_the_limit(tmp_path, out):
    """The fix the message gives is a spacing that passes the same check (no off-by-one in the advice)."""
    case = demo_case(tmp_path, resample={"spacing_mm": 1e-6})
    text = assert_refused(run_limited("build", str(case), "--out", str(out)))
    suggested = float(text.split("use resample.spacing_mm >= ")[1].split()[0])
    assert demo_length_mm(out) / suggested <= MAX_CURVE_SAMPLES
    assert demo_length_mm(out) / (suggested * 0.99) > MAX_CURVE_SAMPLES  # and not needlessly coarse


def test_a_npy_header_claiming_a_huge_array_is_refused_before_allocation(tmp_path, out):
    before = snapshot(out)
    centerline = tmp_path / "centerline.npy"
    with centerline.open("wb") as handle:
        np.lib.format.write_array_header_1_0(
            handle, {"descr": "<f8", "fortran_order": False, "shape": (100_000_000_000, 3)}
        )
        handle.write(np.zeros(30).tobytes())
    case = demo_case(tmp_path, final={"centerline": str(centerline)})
    result = run_limited("build", str(case), "--out", str(out))
    assert_refused(result, str(centerline), "(100000000000, 3)", "the file has", "truncated or corrupt")
    assert snapshot(out) == before


@pytest.mark.slow
def test_a_mesh_at_the_vertex_limit_builds_within_the_memory_budget(prior_build, tmp_path):
    """The bound is not only a refusal: the largest mesh it allows builds under RLIMIT_AS = the budget (about 20 s)."""
    import json

    from softdesign.limits import MAX_ANGULAR_COUNT

    length = demo_length_mm(prior_build)
    # the finest export.spacing_mm check_sizes allows at the most vertices around, rounded up to 0.1 um
    spacing = float(np.ceil(length / (MAX_MESH_VERTICES / MAX_ANGULAR_COUNT - 2) * 1e4) / 1e4)
    out = tmp_path / "build"
    shutil.copytree(prior_build, out)
    case = demo_case(tmp_path, export={"q": [1], "spacing_mm": spacing, "angular_count": MAX_ANGULAR_COUNT})
    result = run_limited("build", str(case), "--out", str(out), timeout=BUILD_TIMEOUT_S)
    assert result.returncode == 0, result.stderr
    vertices = json.loads((out / "export" / "summary.json").read_text())["meshes"]["meshes/q_1.000.stl"]["vertices"]
    # the bound counts rings x angular_count; the caps and the rings at link joints add under ESTIMATE_RTOL
    assert 0.9 * MAX_MESH_VERTICES < vertices <= (1 + ESTIMATE_RTOL) * MAX_MESH_VERTICES
