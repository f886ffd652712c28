"""``blend: auto`` judges the body on the shape the stage keeps, and hands the morph's curves on with it.

The kinematics' export q are the morph grid's (i / 40): the curves the blend's look at the body built are the
ones every later stage asks for, so the stage keeps them on its shape, which must be the very shape a build
loads from the folder (rebuilt from the kept samples), bit for bit, or a stage re-run on a cached blend would
write other bytes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from softdesign.fitting.projection import project_points
from softdesign.geometry.morph_fold import morph_q_grid
from softdesign.pipeline.api import build_through
from softdesign.pipeline.blend_body import WALL_PROJECTION
from softdesign.pipeline.stages.blend import load_blend
from tests.helpers.paths import DEMO


def auto_demo(folder: Path) -> Path:
    """The sample case with ``blend: auto`` (it asks for linear) and absolute input paths."""
    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    case["blend"] = "auto"
    path = folder / "auto.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


@pytest.mark.parametrize("jobs", [1, 2])
def test_the_judged_shape_is_kept_with_its_curves_and_is_the_one_loaded(tmp_path: Path, jobs: int):
    outcome = build_through(auto_demo(tmp_path), tmp_path / "build", target="blend", jobs=jobs)
    built = outcome.results["blend"].shape
    assert outcome.results["blend"].summary["requested"] == "auto"
    q_grid = [float(q) for q in morph_q_grid()]
    assert all(built.built_curve(q) is not None for q in q_grid)  # built by the look at the body, kept
    loaded = load_blend(tmp_path / "build").shape
    for a, b in zip(built.keys, loaded.keys, strict=True):
        assert a.length == b.length
        assert np.array_equal(a.points(a.dense_l()), b.points(b.dense_l()))
    for q in (q_grid[0], q_grid[17], q_grid[-1]):
        kept, again = built.built_curve(q), loaded.curve_at(q)
        assert kept is not None
        assert np.array_equal(kept.dense_frames, again.dense_frames)  # the loaded shape's own curve, bit for bit
        l = kept.dense_l
        assert np.array_equal(kept.points(l), again.points(l))


def test_the_fit_takes_the_rows_the_look_at_the_body_projected_and_gets_the_same_numbers(tmp_path: Path):
    # the fit stage fits around the very curve the blend judged the body on: the rows projected there (every k-th
    # vertex) are taken, not projected again; each point's projection is its own, so the fit's are the same bits
    case = auto_demo(tmp_path)
    through_blend = build_through(case, tmp_path / "blend", target="blend").results
    kept = through_blend["blend"].shape.take(WALL_PROJECTION)
    assert isinstance(kept, tuple) and kept[0] is through_blend["ingest"].vertices
    results = build_through(case, tmp_path / "fit", target="fit").results
    shape = results["links"].chain.shape
    assert shape.take(WALL_PROJECTION) is None  # taken by the fit
    again = project_points(shape.target_curve(), results["ingest"].vertices)
    for name in ("l", "angle", "rho"):
        assert np.array_equal(results["fit"].points[name], getattr(again, name)), name


def test_projecting_with_known_rows_gives_every_point_its_own_numbers():
    from softdesign.geometry.curves import smooth_curve_from_polyline
    from softdesign.geometry.frames import framed_curve

    s = np.linspace(0.0, 1.0, 41)
    curve = framed_curve(smooth_curve_from_polyline(np.column_stack([30 * np.sin(s), 20 * s ** 2, 60 * s])))
    rng = np.random.default_rng(3)
    points = curve.points(rng.uniform(0, 1, 2000)) + rng.normal(0, 2.0, (2000, 3))
    whole = project_points(curve, points)
    rows = slice(None, None, 7)
    part = project_points(curve, points[rows])
    merged = project_points(curve, points, known=(rows, part))
    for name in ("l", "angle", "rho", "end_side"):
        assert np.array_equal(getattr(merged, name), getattr(whole, name)), name
    assert np.array_equal(merged.points, points)
