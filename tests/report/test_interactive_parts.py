"""The 3D view's mould and chamber traces (issue 17, item 2) and its frames' topology.

A straight tube of radius 3 mm (open, its vertices on the cylinder) built hollow (1 mm wall) with a mould has an
analytic chamber: a cylinder of radius rho - wall about the centerline, from
arc length wall to length - wall.  The mould traces are the mould stage's STL
parts, decimated within the view's tolerance.  A solid build without mould
has neither trace (an arc, so that its length changes with q).  The figure is a plain dict written without
plotly's figure classes (``plotly.graph_objects``), in the same JSON as they wrote.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from softdesign.io.formats import read_mesh
from softdesign.pipeline import layout
from softdesign.pipeline.api import build_through
from softdesign.report.build_folder import load_build
from softdesign.report.display_mesh import max_distance_to_mesh
from softdesign.report.interactive import (
    DISPLAY_TOLERANCE_MM,
    TEMPLATE_NONE,
    morph_figure,
    morph_html,
)
from softdesign.report.interactive_parts import CHAMBER_NAME, MOULD_PREFIX
from tests.helpers.parts_cases import LENGTH_MM, WALL_MM, bent_solid_case
from tests.helpers.shared_builds import hollow_tube_build

pytestmark = pytest.mark.slow

FRAMES = 5
#: The fit of points on the cylinder gives rho = 3 mm to its own error: the chamber's radius is rho less the wall,
#: within this.
CHAMBER_RADIUS_ATOL_MM = 0.02
#: Ring positions along the axis come from an arc length table of 2001 samples: far below this.
CHAMBER_END_ATOL_MM = 1e-3


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """A hollow straight tube with a mould, and a solid bent tube without one."""
    folder = tmp_path_factory.mktemp("parts")
    build_through(bent_solid_case(folder), folder / "solid")
    # the hollow tube's build is the run's shared one (the browser test opens its page), only read here
    return load_build(hollow_tube_build(tmp_path_factory)), load_build(folder / "solid")


def named(figure, prefix: str) -> list:
    return [t for t in figure["data"] if t.get("name", "").startswith(prefix)]


def test_every_frame_updates_its_trace_with_the_same_vertex_count(builds):
    """Frames change only x, y, z: each must have as many vertices as the trace's faces were made for, also when
    the body's length changes with q (the bent vessel)."""
    lengths = [builds[1].kinematics.chain.shape.curve_at(q).length for q in (0.5, 1.0)]
    assert lengths[1] - lengths[0] > 1.0  # mm: a ring spacing, so rings about 1 mm apart would differ in count
    for data in builds:
        figure, _ = morph_figure(data, FRAMES)
        for frame in figure["frames"]:
            for index, trace in zip(frame["traces"], frame["data"], strict=True):
                shown = figure["data"][index]
                assert trace["type"] == shown["type"]
                assert len(trace["x"]) == len(shown["x"])
                if shown["type"] == "mesh3d":
                    assert int(np.max(shown["i"])) < len(trace["x"])


def test_the_chamber_is_the_analytic_cylinder_at_every_q_and_hidden_at_first(builds):
    hollow, _ = builds
    figure, notes = morph_figure(hollow, FRAMES)
    (chamber,) = named(figure, CHAMBER_NAME)
    assert chamber["visible"] == "legendonly"
    (index,) = [i for i, t in enumerate(figure["data"]) if t is chamber]
    rho = float(hollow.fit.field.evaluate_grid(1.0, np.array([0.5]), np.linspace(0, 2 * np.pi, 48))[0].mean())
    for frame in figure["frames"]:
        (trace,) = [t for i, t in zip(frame["traces"], frame["data"], strict=True) if i == index]
        points = np.column_stack([trace["x"], trace["y"], trace["z"]]).astype(float)
        rings = points[:-2]  # the two cap centres follow the rings
        np.testing.assert_allclose(np.hypot(rings[:, 0], rings[:, 1]), rho - WALL_MM, atol=CHAMBER_RADIUS_ATOL_MM)
        np.testing.assert_allclose([rings[:, 2].min(), rings[:, 2].max()], [WALL_MM, LENGTH_MM - WALL_MM],
                                   atol=CHAMBER_END_ATOL_MM)
    assert any(n.startswith("chamber:") for n in notes)


def test_the_chamber_lies_on_the_exported_bodys_inner_surface(builds):
    """The displayed chamber at q = 1 against the export's own q = 1 solid (its inner surface), within tolerance."""
    hollow, _ = builds
    figure, _ = morph_figure(hollow, FRAMES)
    (chamber,) = named(figure, CHAMBER_NAME)
    rings = np.column_stack([chamber["x"], chamber["y"], chamber["z"]]).astype(float)[:-2]
    vertices, faces = read_mesh(hollow.build_dir / layout.mesh_path(1.0, "stl"))
    assert max_distance_to_mesh(rings, vertices, faces) <= DISPLAY_TOLERANCE_MM


def test_the_mould_parts_are_the_stages_files_hidden_at_first_and_inside_the_scene(builds):
    hollow, _ = builds
    figure, notes = morph_figure(hollow, FRAMES)
    parts = named(figure, MOULD_PREFIX)
    assert sorted(t["name"].removeprefix(MOULD_PREFIX) for t in parts) == ["core", "half_a", "half_b"]
    scene = figure["layout"]["scene"]
    for trace in parts:
        assert trace["visible"] == "legendonly"
        shown = np.column_stack([trace["x"], trace["y"], trace["z"]]).astype(float)
        part = trace["name"].removeprefix(MOULD_PREFIX)
        vertices, faces = read_mesh(hollow.build_dir / layout.mould_path(part, "stl"))
        # decimated within the display tolerance: every vertex of the part is that close to the shown mesh
        faces_shown = np.column_stack([trace["i"], trace["j"], trace["k"]])
        assert max_distance_to_mesh(vertices, shown, faces_shown) <= DISPLAY_TOLERANCE_MM
        for axis, column in zip((scene["xaxis"], scene["yaxis"], scene["zaxis"]), shown.T, strict=True):
            assert axis["range"][0] <= column.min() and column.max() <= axis["range"][1]
    assert sum(n.startswith("mould ") for n in notes) == 3


def test_a_solid_build_without_mould_has_neither_trace(builds):
    _, solid = builds
    figure, notes = morph_figure(solid, FRAMES)
    assert named(figure, CHAMBER_NAME) == [] and named(figure, MOULD_PREFIX) == []
    assert not any(n.startswith(("chamber", "mould")) for n in notes)


def test_the_view_with_mould_and_chamber_is_the_same_bytes_twice(builds):
    hollow, _ = builds
    assert morph_html(hollow, FRAMES) == morph_html(hollow, FRAMES)


#: Run in a fresh interpreter (other tests import plotly's figure classes): the view of a build with every trace
#: kind, then the plotly modules loaded.  plotly.io itself imports the package plotly.graph_objs, which loads its
#: classes (plotly.graph_objs.*) and their validators only when one is used.
NO_FIGURE_CLASSES = """
import sys
from softdesign.report.build_folder import load_build
from softdesign.report.interactive import morph_html
html, _ = morph_html(load_build(sys.argv[1]), int(sys.argv[2]))
assert 'Plotly.newPlot' in html and 'Plotly.addFrames' in html
print("\\n".join(sorted(m for m in sys.modules if "plotly" in m)))
"""


def test_the_view_is_written_without_plotlys_figure_classes(builds):
    """Validating every property of every trace and frame was about half the view's time: the figure is a dict."""
    hollow, _ = builds
    done = subprocess.run([sys.executable, "-c", NO_FIGURE_CLASSES, str(hollow.build_dir), str(FRAMES)],
                          capture_output=True, text=True, check=True)
    loaded = done.stdout.split()
    assert "plotly.io._html" in loaded  # what the check looks at is there
    assert [m for m in loaded if m.startswith(("plotly.graph_objs.", "plotly.graph_objects", "plotly.validator"))] \
        == []


def test_the_layouts_template_is_plotlys_template_none():
    """The figure classes wrote template="none" as this JSON: the page's look is plotly.js's own defaults."""
    import plotly.graph_objects as go

    assert go.Figure(layout={"template": "none"}).to_dict()["layout"]["template"] == TEMPLATE_NONE
