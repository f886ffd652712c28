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

from softdesign.geometry.morph_fold import morph_q_grid
from softdesign.pipeline.api import build_through
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
