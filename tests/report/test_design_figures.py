"""The report's design panel (issue 14, item 3): what it draws is the build's own arc check."""

from __future__ import annotations

import json

import numpy as np
from PIL import Image

from softdesign.kinematics.arc_design import chain_tip_error
from softdesign.pipeline.api import build_through
from softdesign.report.design_figures import design_picture, design_series
from softdesign.report.writer import EXPECTED_SIZES
from tests.helpers.paths import REPO

#: Distances and chained points are the same computations on the same samples: rounding only, mm.
SAME_TOL_MM = 1e-9


def test_the_panel_draws_the_manifests_deviations_and_the_chained_tip(tmp_path):
    outcome = build_through(REPO / "configs" / "demo.yaml", tmp_path / "build", target="kinematics")
    chain = outcome.results["kinematics"].chain
    series = design_series(chain)
    manifest = json.loads((tmp_path / "build" / "manifest.json").read_text())
    deviations = manifest["metrics"]["kinematics"]["arc_check"]["max_deviation_mm"]
    np.testing.assert_allclose([d.max() for d in series["distance"]], deviations, rtol=0, atol=SAME_TOL_MM)
    # each drawn arc starts on its link's start point; the chain starts at the base and ends where the D-H tip is
    curve = chain.shape.curve_at(1.0)
    np.testing.assert_allclose([a[0] for a in series["arcs"]], curve.points(chain.breaks[:-1]), rtol=0,
                               atol=SAME_TOL_MM)
    chained = series["chained"][0]
    from softdesign.kinematics.arc_check import link_arcs_at_final_shape

    grid = chain.shape.smooth_curve_at(1.0).l_grid
    tip_mm, _ = chain_tip_error(tuple(link_arcs_at_final_shape(chain)), curve.frames(grid), curve.points(grid))
    np.testing.assert_allclose(np.linalg.norm(chained[-1] - curve.points([1.0])[0]), tip_mm, rtol=0, atol=1e-6)
    assert tip_mm > 1.0  # four links of the tortuous demo, each 1.9-2.8 mm off: the chain drifts by more
    picture = design_picture(chain)
    path = tmp_path / picture.name
    path.write_bytes(picture.data)
    with Image.open(path) as image:
        assert image.size == EXPECTED_SIZES["design.png"]


def test_with_a_design_the_panel_draws_the_composed_chain_and_its_figures(tmp_path):
    # issue 30: a build with a design: block shows the chain composed from the base, its deviation and tip error
    import yaml

    from softdesign.pipeline.stages.design import load_design
    from softdesign.report.design_figures import panel_picture, panel_title

    demo = REPO / "configs" / "demo.yaml"
    case = yaml.safe_load(demo.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((demo.parent / case["final"][key]).resolve())
    case.update(design={"tolerance_mm": 1.0}, blend="pcc")
    case_file = tmp_path / "demo.yaml"
    case_file.write_text(yaml.safe_dump(case))
    outcome = build_through(case_file, tmp_path / "build", target="kinematics")
    design = load_design(tmp_path / "build")
    assert design is not None and panel_title(tmp_path / "build").startswith("Design: constant-curvature sections")
    picture = panel_picture(outcome.results["kinematics"].chain, tmp_path / "build")
    document = design.document
    for figure in (document["chain_max_deviation_mm"], document["tip_error_mm"], document["tip_error_deg"]):
        assert f"{figure:.3g}" in picture.caption
    path = tmp_path / picture.name
    path.write_bytes(picture.data)
    with Image.open(path) as image:
        assert image.size == EXPECTED_SIZES["design.png"]
    # the profile drawn is each target sample's distance to the chain, at most the chain's two-way deviation
    assert 0.0 < design.profile["deviation_mm"].max() <= document["chain_max_deviation_mm"]


def test_the_legends_sit_below_their_axes_and_inside_the_figure(tmp_path, monkeypatch):
    # issue 34: design.png's legend covered the curves; each legend is now below its axes, whole, in the picture
    from softdesign.report import design_figures

    outcome = build_through(REPO / "configs" / "demo.yaml", tmp_path / "build", target="kinematics")
    drawn = []
    real = design_figures.picture

    def keep(name, figure, size_in, title, caption):
        drawn.append(figure)
        return real(name, figure, size_in, title, caption)

    monkeypatch.setattr(design_figures, "picture", keep)
    design_figures.design_picture(outcome.results["kinematics"].chain)
    figure = drawn[0]
    renderer = figure.canvas.get_renderer()
    whole = figure.bbox
    for axes in figure.axes:
        legend = axes.get_legend().get_window_extent(renderer)
        assert not legend.overlaps(axes.get_window_extent(renderer))
        assert not legend.overlaps(axes.xaxis.get_tightbbox(renderer))  # the tick labels and the x label
        assert whole.x0 <= legend.x0 and legend.x1 <= whole.x1 and whole.y0 <= legend.y0 and legend.y1 <= whole.y1
