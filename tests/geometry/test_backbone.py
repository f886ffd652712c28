"""The backbone regularization: left alone where the vessel allows the turn, smoothed locally where it does not."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.config import Case
from softdesign.geometry import backbone as bb
from softdesign.geometry.backbone import TARGET_REACH, reach_along, regularize_backbone
from softdesign.geometry.curves import CurveOptions
from softdesign.geometry.network import SelectedPath
from softdesign.pipeline.backbone_step import regularized_path
from tests.helpers.robust_vessels import stub_turn_axis

OPTIONS = CurveOptions(spacing_mm=0.5, smoothing_mm=0.1, end_straight_mm=2.0)
RADIUS = 6.0
#: a stub, then 60 degrees within half a radius of arc (bend radius 0.5 r / (pi / 3)), then a tail
TIGHT = stub_turn_axis(4.5, 0.5 * RADIUS / (np.pi / 3), 60.0, 50.0)[0]


def test_a_turn_the_vessel_allows_is_left_exactly_as_it_is():
    points = stub_turn_axis(4.5, 20.0, 60.0, 30.0)[0]  # bend radius 20 mm: r * kappa 0.3
    reg = regularize_backbone(points, np.full(len(points), RADIUS), OPTIONS)
    assert not reg.regularized and np.array_equal(reg.points, points) and not reg.moved_mm.any()
    assert reg.summary()["stretches"] == []


def test_a_turn_within_half_a_radius_is_smoothed_below_the_target_reach():
    radius = np.full(len(TIGHT), RADIUS)
    before, _ = reach_along(TIGHT, radius, OPTIONS)
    reg = regularize_backbone(TIGHT, radius, OPTIONS)
    after, _ = reach_along(reg.points, radius, OPTIONS)
    assert before.max() >= 1.0 and reg.regularized
    assert after.max() < TARGET_REACH and reg.reach_after == pytest.approx(after.max())
    assert len(reg.points) == len(TIGHT)


def test_the_regularized_backbone_keeps_its_end_planes_and_is_untouched_past_the_ramp():
    reg = regularize_backbone(TIGHT, np.full(len(TIGHT), RADIUS), OPTIONS)
    [stretch] = reg.stretches
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(TIGHT, axis=0), axis=1))])
    # past the blend-in ramp (at most RAMP_SIGMAS widths past the turn's end, 7.6 mm) nothing moves at all
    beyond = s > 7.6 + bb.RAMP_SIGMAS * stretch.sigma_mm
    assert beyond.sum() > 10 and np.array_equal(reg.points[beyond], TIGHT[beyond])
    assert np.array_equal(reg.points[-1], TIGHT[-1])
    # the inlet moves only within its normal plane (the cap's), and keeps its tangent: the continuation past
    # the end is the mirror image, so the smoothed curve is mirror-symmetric there
    t_in = (TIGHT[1] - TIGHT[0]) / np.linalg.norm(TIGHT[1] - TIGHT[0])
    assert abs((reg.points[0] - TIGHT[0]) @ t_in) < 1e-9 * RADIUS
    t_out = reg.points[1] - reg.points[0]
    assert np.degrees(np.arccos(t_in @ t_out / np.linalg.norm(t_out))) < 2.0
    assert reg.moved_mm.max() == pytest.approx(stretch.max_moved_mm) and 0.0 < stretch.max_moved_mm < RADIUS
    # the stretch reported is where the backbone moved by more than 1% of the radius
    inside = (s >= stretch.from_mm) & (s <= stretch.to_mm)
    assert np.all(reg.moved_mm[~inside] <= bb.MOVED_FRACTION * RADIUS)


def test_the_tangent_stays_continuous_no_kink_between_consecutive_segments():
    reg = regularize_backbone(TIGHT, np.full(len(TIGHT), RADIUS), OPTIONS)
    seg = np.diff(reg.points, axis=0)
    step = np.linalg.norm(seg, axis=1)
    turn = np.arccos(np.clip(np.sum(seg[1:] * seg[:-1], axis=1) / (step[1:] * step[:-1]), -1.0, 1.0))
    # discrete curvature (turn per mm) times the radius: below 1 everywhere, where the input reaches 2
    assert np.max(turn / step[1:]) * RADIUS < 1.0
    seg0 = np.diff(TIGHT, axis=0)
    turn0 = np.arccos(np.clip(np.sum(seg0[1:] * seg0[:-1], axis=1) / np.linalg.norm(seg0[1:], axis=1)
                              / np.linalg.norm(seg0[:-1], axis=1), -1.0, 1.0))
    assert np.max(turn0 / np.linalg.norm(seg0[1:], axis=1)) * RADIUS > 1.9


def test_a_turn_no_width_tried_can_smooth_is_left_as_it_is_with_a_warning_naming_the_place(monkeypatch):
    monkeypatch.setattr(bb, "SIGMA_FACTORS", (0.05,))
    path = SelectedPath(TIGHT, np.full(len(TIGHT), RADIUS), 0)
    same, summary = regularized_path(Case.model_validate({"name": "t", "final": {"centerline": "c.vtp"}}), path)
    assert np.array_equal(same.points, TIGHT) and summary is not None and not summary["regularized"]
    assert summary["unresolved"]["reach"] >= TARGET_REACH and 0.0 < summary["unresolved"]["l"] < 1.0
    [warning, inscribed] = same.notes
    assert warning.startswith("warning: the centerline turns tighter than the vessel is wide at")
    assert "l = 0." in warning
    assert "the fit checks whether the fitted body folds there" in warning
    assert inscribed.startswith("warning: at ") and "r * kappa = " in inscribed


def test_without_inscribed_radii_nothing_is_checked():
    path = SelectedPath(TIGHT, None, 0)
    same, summary = regularized_path(Case.model_validate({"name": "t", "final": {"centerline": "c.vtp"}}), path)
    assert same is path and summary is None
