"""`softdesign validate` opens every input file (issue 29 item 5), and each refusal's fix works (item 6).

Each refusal test applies the fix the message offers to the same case and shows validate then passes.
"""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.cases import straight_tube, write_case
from tests.helpers.segment_files import segments_of, write_segments

runner = CliRunner()


def _validate(case):
    result = runner.invoke(app, ["validate", str(case)])
    assert "Traceback" not in result.output
    return result


def _refused(case, *needles):
    result = _validate(case)
    assert result.exit_code == 2, result.output
    for needle in needles:
        assert needle in result.output, (needle, result.output)
    return result.output


def test_every_input_is_opened_and_described(tmp_path):
    centerline, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": str(centerline), "surface": str(surface)})
    result = _validate(case)
    assert result.exit_code == 0, result.output
    assert "2 input file(s) opened" in result.output
    assert "final.centerline centerline.vtp: VTK XML PolyData: 81 points, 1 lines; point arrays " \
           "MaximumInscribedSphereRadius" in result.output
    assert "path 0: 81 points, 40.00 mm, radius 3 to 3 mm" in result.output
    assert "extent 0 x 0 x 40 mm" in result.output
    assert "final.surface surface.stl: STL:" in result.output and "triangles" in result.output


def test_an_stl_given_as_the_centerline_is_refused_and_auto_fixes_it(tmp_path):
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": str(surface)})
    _refused(case, "final.centerline:", "is a surface mesh (STL), not a centerline",
             "give it as final.surface and set final.centerline: auto")
    fixed = write_case(tmp_path, "fixed", final={"centerline": "auto", "surface": str(surface)})
    assert _validate(fixed).exit_code == 0


def test_an_stl_given_as_a_keyframe_centerline_names_softdesign_centerline(tmp_path):
    from softdesign.io.formats import write_mesh
    from tests.helpers.vessels import straight_tube as open_tube

    centerline, surface = straight_tube(tmp_path)
    tube = tmp_path / "open.stl"
    write_mesh(tube, *open_tube(radius=3.0, length=40.0, edge=0.6))
    final = {"centerline": str(centerline), "surface": str(surface)}
    case = write_case(tmp_path, final=final, intermediate=[{"q": 0.5, "centerline": str(tube)}])
    output = _refused(case, "intermediate[0].centerline:", "softdesign centerline")
    # the fix as the message words it: compute the centerline, give that file
    command = output.split("(softdesign centerline ")[1].split(")")[0].split()
    out = tmp_path / command[-1]
    assert runner.invoke(app, ["centerline", command[0], "--output", str(out)]).exit_code == 0
    fixed = write_case(tmp_path, "fixed", final=final, intermediate=[{"q": 0.5, "centerline": str(out)}])
    assert _validate(fixed).exit_code == 0


def test_segments_that_cannot_be_joined_are_refused_and_auto_fixes_it(tmp_path):
    _, surface = straight_tube(tmp_path)
    z = np.linspace(0.0, 40.0, 21)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    bits = write_segments(tmp_path / "bits.vtk", points, np.array([[k, k + 1] for k in range(0, 20, 2)]))
    case = write_case(tmp_path, final={"centerline": str(bits), "surface": str(surface)})
    _refused(case, "10 line cells are short segments that join into no path", "final.centerline: auto")
    fixed = write_case(tmp_path, "fixed", final={"centerline": "auto", "surface": str(surface)})
    assert _validate(fixed).exit_code == 0


def test_segments_that_close_a_loop_are_refused_and_a_computed_centerline_fixes_it(tmp_path):
    from softdesign.io.formats import write_mesh
    from tests.helpers.vessels import straight_tube as open_tube

    surface = tmp_path / "open.stl"  # fine, even edges: what centerline extraction expects
    write_mesh(surface, *open_tube(radius=3.0, length=40.0, edge=0.6))
    t = np.linspace(0.0, 2 * np.pi, 40, endpoint=False)
    ring = np.column_stack([np.cos(t), np.sin(t), 20.0 + 0 * t])
    loop = write_segments(tmp_path / "loop.vtu", ring, np.stack([np.arange(40), (np.arange(40) + 1) % 40], axis=1))
    case = write_case(tmp_path, final={"centerline": str(loop), "surface": str(surface)})
    _refused(case, "close a loop", "softdesign centerline")
    out = tmp_path / "computed.vtp"
    assert runner.invoke(app, ["centerline", str(surface), "--output", str(out)]).exit_code == 0
    fixed = write_case(tmp_path, "fixed", final={"centerline": str(out), "surface": str(surface)})
    assert _validate(fixed).exit_code == 0


def test_gmsh_segments_are_described_as_joined(tmp_path):
    centerline, surface = straight_tube(tmp_path)
    z = np.linspace(0.0, 40.0, 41)
    points, segments = segments_of([np.column_stack([0 * z, 0 * z, z])])
    gmsh = write_segments(tmp_path / "gmsh.vtk", points, segments)
    result = _validate(write_case(tmp_path, final={"centerline": str(gmsh), "surface": str(surface)}))
    assert result.exit_code == 0, result.output
    assert "legacy VTK unstructured grid: 41 points, 40 lines; no data arrays" in result.output
    assert "40 line segments (legacy VTK unstructured grid) joined into 1 path(s)" in result.output
    assert "no radius in the file (ingest measures it on final.surface)" in result.output


@pytest.mark.parametrize("auto", [False, True])
def test_a_wrong_unit_is_caught_by_validate_and_the_named_units_fix_it(tmp_path, auto):
    centerline, surface = straight_tube(tmp_path)  # millimetres
    final = {"centerline": "auto" if auto else str(centerline), "surface": str(surface)}
    case = write_case(tmp_path, units="m", final=final)
    # a surface alone has no radius to tell mm from cm (42 mm or 420 mm long are both vessels): both are named
    fix = ("with units: mm it would be 42 mm long, or with units: cm", "set the case file's units: to those") \
        if auto else ("set units: mm in the case file",)
    output = _refused(case, "with units: m the vessel is", *fix)
    assert "opened" not in output  # refused: no "valid" line
    fixed = write_case(tmp_path, "fixed", units="mm", final=final)
    assert _validate(fixed).exit_code == 0


def test_a_surface_in_other_units_is_caught_and_surface_units_fixes_it(tmp_path):
    centerline, _ = straight_tube(tmp_path)
    metres = tmp_path / "metres"
    metres.mkdir()
    _, surface = straight_tube(metres, scale=1e-3)
    final = {"centerline": str(centerline), "surface": str(surface)}
    _refused(write_case(tmp_path, final=final), "a units mismatch would explain it (surface in m, centerline in mm)",
             "set final.surface_units")
    fixed = write_case(tmp_path, "fixed", final={**final, "surface_units": "m"})
    assert _validate(fixed).exit_code == 0


def test_build_refuses_a_wrong_unit_of_an_auto_case_before_extracting_and_the_named_units_fix_it(tmp_path):
    from softdesign.io.formats import write_mesh
    from tests.helpers.vessels import straight_tube as open_tube

    surface = tmp_path / "open.stl"
    write_mesh(surface, *open_tube(radius=3.0, length=40.0, edge=0.6))  # millimetres
    final = {"centerline": "auto", "surface": str(surface)}
    case = write_case(tmp_path, units="m", final=final)
    result = runner.invoke(app, ["ingest", str(case), "--out", str(tmp_path / "build")])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert "final.surface open.stl (its largest extent): with units: m" in result.output
    assert "with units: mm it would be" in result.output
    assert not (tmp_path / "build" / "ingest").exists()  # nothing extracted, nothing written
    fixed = write_case(tmp_path, "fixed", units="mm", final=final)
    result = runner.invoke(app, ["ingest", str(fixed), "--out", str(tmp_path / "build")])
    assert result.exit_code == 0, result.output
