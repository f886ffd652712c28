"""Every matplotlib figure of the demo's report: no label leaves the image, no two panels' labels overlap.

The report lays out most figures on fixed grids (:func:`softdesign.report.plotting.fixed_figure`) rather than
matplotlib's constrained layout; this checks, on the drawn figures, what the constrained layout would have
ensured: each axes' tight box (ticks, labels, title, colour bar) inside the figure and apart from the others'.
"""

from __future__ import annotations

import itertools
from typing import Any

import pytest

from softdesign.report import plotting
from softdesign.report.writer import ReportOptions, write_report
from tests.helpers.shared_builds import demo_build_copy

pytestmark = pytest.mark.slow

#: Text extents are measured in pixels; a box may touch its neighbour or the edge by antialiasing's one pixel.
OVERLAP_TOLERANCE_PX = 1.0


def _boxes_of(figure) -> dict[str, Any]:
    """Tight boxes as the figure was saved (no new draw: a layout engine would move the axes again)."""
    renderer = figure.canvas.get_renderer()
    boxes = {f"axes {k} ({ax.get_title() or ax.get_label()})": ax.get_tightbbox(renderer)
             for k, ax in enumerate(figure.axes) if ax.get_visible() and ax.axison}
    boxes.update({f"legend {k}": legend.get_window_extent(renderer) for k, legend in enumerate(figure.legends)})
    return boxes


def _overlap(a, b) -> float:
    return min(max(0.0, min(a.x1, b.x1) - max(a.x0, b.x0)), max(0.0, min(a.y1, b.y1) - max(a.y0, b.y0)))


@pytest.fixture(scope="module")
def drawn_boxes(tmp_path_factory):
    build_dir = demo_build_copy(tmp_path_factory, tmp_path_factory.mktemp("layout") / "build")
    boxes: dict[str, tuple[tuple[float, float], dict[str, Any]]] = {}
    real_png_bytes = plotting.png_bytes

    def checked(figure) -> bytes:
        data = real_png_bytes(figure)
        width, height = figure.get_size_inches() * plotting.DPI
        boxes[f"figure {len(boxes)} ({width:g} x {height:g} px)"] = (float(width), float(height)), _boxes_of(figure)
        return data

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plotting, "png_bytes", checked)
        # the figures as drawn (the kinematics plot's q samples included); the GIF and the 3D view, which no figure
        # of this check draws, with 3 frames each
        write_report(build_dir, ReportOptions(gif_frames=3, view_frames=3), jobs=1)
    return boxes


def test_every_report_figure_was_checked(drawn_boxes):
    # morph, surfaces, profile, residuals, distances, kinematics, design, stretch (the GIF is drawn apart)
    assert len(drawn_boxes) == 8


def test_no_label_leaves_a_report_figure(drawn_boxes):
    for figure, ((width, height), boxes) in drawn_boxes.items():
        for name, box in boxes.items():
            assert min(box.x0, box.y0) >= -OVERLAP_TOLERANCE_PX, f"{figure}: {name} leaves the image at left or bottom"
            assert box.x1 <= width + OVERLAP_TOLERANCE_PX, f"{figure}: {name} leaves the image at the right"
            assert box.y1 <= height + OVERLAP_TOLERANCE_PX, f"{figure}: {name} leaves the image at the top"


def test_no_two_panels_labels_overlap(drawn_boxes):
    for figure, (_, boxes) in drawn_boxes.items():
        for (a, box_a), (b, box_b) in itertools.combinations(boxes.items(), 2):
            assert _overlap(box_a, box_b) <= OVERLAP_TOLERANCE_PX, f"{figure}: {a} overlaps {b}"
