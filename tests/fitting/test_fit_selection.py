"""Wall-point selection on a synthetic Y network whose every point's fate is known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, InputDataError
from softdesign.fitting.projection import project_points
from softdesign.fitting.selection import (
    NetworkContext,
    SelectionSettings,
    inscribed_profile,
    polyline_distances,
    select_wall_points,
)
from tests.helpers.analytic import Line

RADIUS = 3.0
#: The other branch leaves the trunk at z = 40 at 45 degrees, in the xz plane.
BRANCH_DIR = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5)])
JUNCTION = np.array([0.0, 0.0, 40.0])
#: Distances are closed-form segment distances: rounding only.
DISTANCE_TOL_MM = 1e-12


def _ring(axis_point, direction, radius, count):
    """Points on a circle around ``direction`` through ``axis_point``."""
    u = np.cross(direction, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(direction, u)
    a = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    return axis_point + radius * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * v)


def _dome(centre, direction, radius):
    """A hemisphere of points beyond ``centre`` along ``direction`` (the pole excluded)."""
    rings = [_ring(centre + radius * np.cos(t) * direction, direction, radius * np.sin(t), 12)
             for t in np.radians([15, 35, 55, 75])]
    return np.concatenate(rings)


def _y_network(trunk_offset_mm=0.0):
    """Path: z axis 0..80 mm.  Other: the same trunk to z = 40 (shifted along +x), then 40 mm along BRANCH_DIR."""
    path = np.column_stack([np.zeros(81), np.zeros(81), np.arange(81.0)])
    branch = JUNCTION + np.arange(1.0, 41.0)[:, None] * BRANCH_DIR
    other = np.concatenate([path[:41] + [trunk_offset_mm, 0.0, 0.0], branch])
    return path, other


def _surface():
    """Labelled points: path wall away from the junction, the other branch's wall, three domes, outliers."""
    z_axis = np.array([0.0, 0.0, 1.0])
    # Path wall only where the other branch's axis is farther than RADIUS, so the label is unambiguous:
    # the wall point (3, 0, z) is |3 - (z - 40)| / sqrt(2) from the branch axis (> 3 for z > 47.3), and
    # 5 mm or more from its start (0, 0, 40) for z <= 36.
    wall = np.concatenate([_ring([0, 0, z], z_axis, RADIUS, 16) for z in [*range(2, 37, 2), *range(50, 79, 2)]])
    branch_wall = np.concatenate([_ring(JUNCTION + t * BRANCH_DIR, BRANCH_DIR, RADIUS, 16) for t in range(10, 39, 2)])
    path_dome = _dome(np.array([0.0, 0.0, 80.0]), z_axis, RADIUS)
    inlet_dome = _dome(np.zeros(3), -z_axis, RADIUS)
    branch_end = JUNCTION + 40.0 * BRANCH_DIR
    branch_dome = _dome(branch_end, BRANCH_DIR, RADIUS)
    outliers = np.array([[-2.5 * RADIUS, 0.0, z] for z in (10.0, 20.0, 30.0)])
    parts = {"kept": wall, "other_branch": np.concatenate([branch_wall, branch_dome]),
             "cap": np.concatenate([path_dome, inlet_dome]), "outlier": outliers}
    return parts


def _select(parts, settings=SelectionSettings(), with_radius=True, trunk_offset_mm=0.0):
    curve = Line(80.0)
    path, other = _y_network(trunk_offset_mm)
    points = np.concatenate(list(parts.values()))
    polar = project_points(curve, points)
    if with_radius:
        l, r = inscribed_profile(curve, path, np.full(len(path), RADIUS))
        network = NetworkContext(path, (other,), l, r)
    else:
        network = NetworkContext(path, (other,))
    return select_wall_points(polar, curve.length, network, settings)


@pytest.mark.parametrize(
    "with_radius, trunk_offset_mm",
    # A trunk written twice with 0.01 mm between the copies is still shared (shared_tol_mm = 0.05):
    # without that rule the +x wall of the trunk would be nearer the other polyline and dropped.
    [(True, 0.0), (False, 0.0), (True, 0.01)],
    ids=["inscribed_radius", "local_median", "near_coincident_trunk"],
)
def test_every_reason_is_counted_on_a_y_network(with_radius, trunk_offset_mm):
    parts = _surface()
    selection = _select(parts, with_radius=with_radius, trunk_offset_mm=trunk_offset_mm)
    expected = {name: len(p) for name, p in parts.items()}
    assert selection.counts == {"input": sum(expected.values()), **expected}
    # And point by point, not only in total.
    codes = {"kept": 0, "other_branch": 1, "cap": 2, "outlier": 3}
    labels = np.concatenate([np.full(len(p), codes[name]) for name, p in parts.items()])
    np.testing.assert_array_equal(selection.reason, labels)
    np.testing.assert_array_equal(selection.keep, labels == 0)


def test_the_far_dome_of_the_other_branch_is_the_other_branch_not_the_path():
    # Its foot on the path lies inside (z ~ 70), so only the end-clamped distance to the other polyline catches it.
    dome = _dome(JUNCTION + 40.0 * BRANCH_DIR, BRANCH_DIR, RADIUS)
    selection = _select({"other_branch": dome}, SelectionSettings(outlier_factor=100.0))
    assert selection.counts["other_branch"] == len(dome)


def _flat_capped_tube(overshoot_mm):
    """Labelled points of a round tube z in [0, 60] mm closed by flat caps, shifted ``overshoot_mm`` along +z.

    Wall: rings every mm (the rims at z = 0 and 60 included), 24 angles.  Each cap: a hub vertex
    on the axis and rings at 1/4, 1/2 and 0.7 of the radius, as flat capping with inner rings makes.
    The path runs from z = 0 to 60 + 2 overshoot: the caps lie that far inside its ends.
    """
    z_axis = np.array([0.0, 0.0, 1.0])
    rims = [_ring([0.0, 0.0, z], z_axis, RADIUS, 24) for z in (0.0, 60.0)]
    wall = np.concatenate([_ring([0.0, 0.0, z], z_axis, RADIUS, 24) for z in range(1, 60)])
    caps = np.concatenate([np.concatenate([[[0.0, 0.0, z]], *(_ring([0.0, 0.0, z], z_axis, f * RADIUS, 24)
                                                               for f in (0.25, 0.5, 0.7))]) for z in (0.0, 60.0)])
    shift = np.array([0.0, 0.0, overshoot_mm])
    parts = {"wall": wall + shift, "rim": np.concatenate(rims) + shift, "cap": caps + shift}
    return parts, Line(60.0 + 2 * overshoot_mm)


@pytest.mark.parametrize("with_radius", [True, False], ids=["inscribed_radius", "local_median"])
@pytest.mark.parametrize("overshoot_mm", [0.0, 0.05, 0.3])
def test_flat_caps_with_a_hub_on_the_axis_are_caps(overshoot_mm, with_radius):
    # At 0 the caps lie in the end planes (feet clamped to the ends); at 0.05 and 0.3 mm the path runs
    # through them, as a smoothed centerline does, and only "inside the wall beside the end" finds them.
    parts, curve = _flat_capped_tube(overshoot_mm)
    points = np.concatenate(list(parts.values()))
    path = curve.points(np.linspace(0.0, 1.0, 61))
    inscribed = inscribed_profile(curve, path, np.full(61, RADIUS)) if with_radius else (None, None)
    selection = select_wall_points(project_points(curve, points), curve.length, NetworkContext(path, (), *inscribed))
    labels = np.concatenate([np.full(len(p), name) for name, p in parts.items()])
    assert np.all(selection.reason[labels == "cap"] == 2)  # hubs and rings: 2 x (1 + 3 x 24)
    assert np.all(selection.keep[labels == "wall"])
    # The rims are wall and cap at once: dropped with their cap where it is in the end plane, else kept.
    rims = 0 if overshoot_mm > 0 else 48
    assert selection.counts == {"input": len(points), "kept": 59 * 24 + 48 - rims, "other_branch": 0,
                                "cap": 146 + rims, "outlier": 0}


def test_a_point_near_the_axis_is_an_outlier():
    parts = _surface()
    hubs = np.array([[0.0, 0.0, 20.0], [0.5, 0.0, 30.0], [0.0, -1.4, 60.0]])  # below RADIUS / 2 = 1.5 mm
    selection = _select({**parts, "near_axis": hubs})
    assert selection.counts["outlier"] == len(parts["outlier"]) + 3
    np.testing.assert_array_equal(selection.reason[-3:], 3)


def test_end_margin_moves_wall_near_the_ends_to_caps():
    parts = _surface()
    selection = _select(parts, SelectionSettings(end_margin_mm=3.0))
    # Rings at z = 2 and z = 78 are within 3 mm of an end: 2 x 16 wall points become caps.
    assert selection.counts["kept"] == len(parts["kept"]) - 32
    assert selection.counts["cap"] == len(parts["cap"]) + 32


def test_polyline_distance_is_to_the_end_clamped_segments():
    polyline = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]])
    points = np.array([[5.0, 3.0, 0.0], [-4.0, 3.0, 0.0], [13.0, 14.0, 0.0], [12.0, 5.0, 0.0]])
    np.testing.assert_allclose(polyline_distances(points, polyline), [3.0, 5.0, 5.0, 2.0], rtol=0, atol=DISTANCE_TOL_MM)
    only_first = np.array([True, False])
    np.testing.assert_allclose(polyline_distances(points[3:], polyline, only_first), [np.hypot(2, 5)], rtol=0,
                               atol=DISTANCE_TOL_MM)


def test_polyline_distance_is_the_least_over_every_segment_on_a_folded_uneven_polyline():
    # Pruning by nearest midpoints must not change a distance: a hairpin whose two legs pass 0.3 mm
    # apart, segments from 0.01 to 12 mm long, points near and far, compared with every segment.
    rng = np.random.default_rng(7)
    t = np.concatenate([np.linspace(0.0, np.pi, 300), [np.pi + 0.001, 4.0, 7.0]])
    polyline = np.column_stack([20.0 * np.cos(t), 0.15 * np.sign(np.cos(t)) + np.sin(t), t])
    points = np.concatenate([polyline[::7] + rng.normal(scale=0.2, size=(len(polyline[::7]), 3)),
                             rng.normal(scale=15.0, size=(400, 3))])
    start, edge = polyline[:-1], np.diff(polyline, axis=0)
    u = np.clip(np.einsum("nsj,sj->ns", points[:, None] - start, edge) / np.sum(edge**2, axis=1), 0.0, 1.0)
    brute = np.min(np.linalg.norm(points[:, None] - (start + u[:, :, None] * edge), axis=2), axis=1)
    np.testing.assert_allclose(polyline_distances(points, polyline), brute, rtol=0, atol=DISTANCE_TOL_MM)
    some = rng.random(len(edge)) < 0.5
    brute_some = np.min(np.linalg.norm(points[:, None] - (start + u[:, :, None] * edge)[:, some], axis=2), axis=1)
    np.testing.assert_allclose(polyline_distances(points, polyline, some), brute_some, rtol=0, atol=DISTANCE_TOL_MM)


def test_a_path_alone_has_no_other_branch_points():
    parts = _surface()
    points = np.concatenate([parts["kept"], parts["other_branch"]])
    curve = Line(80.0)
    path, _ = _y_network()
    selection = select_wall_points(project_points(curve, points), curve.length, NetworkContext(path),
                                   SelectionSettings(outlier_factor=100.0))
    assert selection.counts["other_branch"] == 0


def test_inscribed_profile_is_sorted_by_l_and_checked():
    path = np.column_stack([np.zeros(5), np.zeros(5), [80.0, 60.0, 40.0, 20.0, 0.0]])
    l, r = inscribed_profile(Line(80.0), path, np.array([5.0, 4.0, 3.0, 2.0, 1.0]))
    np.testing.assert_allclose(l, [0.0, 0.25, 0.5, 0.75, 1.0], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(r, [1.0, 2.0, 3.0, 4.0, 5.0])
    with pytest.raises(InputDataError, match="MaximumInscribedSphereRadius must be positive"):
        inscribed_profile(Line(80.0), path, np.array([5.0, 4.0, 0.0, 2.0, 1.0]))
    with pytest.raises(ConfigError, match="outlier_factor must be > 1, got 0.5"):
        SelectionSettings(outlier_factor=0.5)
    with pytest.raises(ConfigError, match="cap_inner_fraction in \\(0, 1\\), got 1.0, 1.2"):
        SelectionSettings(cap_inner_fraction=1.2)
