"""Our centerlines of the VMTK aorta against VMTK's own (``aorta-centerline.vtp``), both surfaces.

VMTK's centerlines were computed by ``vmtkcenterlines`` with seeds a user picked; ours find their
endpoints alone (the openings of the open surface; the graph's extremities on the capped one, whose ends
are rounded, not flat).  The two conventions place the ends differently, so the figures are taken away
from the first and last inscribed radius of each path, ours and VMTK's (issue 18).
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.centerline.extract import extract_centerlines
from softdesign.io.centerline import read_centerline_network
from softdesign.io.surface import read_surface

#: Issue 18's targets: mean and max distance from our points to VMTK's polyline, mm ...
MEAN_TOL_MM, MAX_TOL_MM = 0.1, 0.5
#: ... and the median relative difference of the inscribed radius.
RADIUS_MEDIAN_RTOL = 0.03


def _distinct(points: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9])
    return points[keep], radius[keep]


def _foot(points: np.ndarray, polyline: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance to the polyline (n,), the segment (n,) and the fraction along it (n,) of each point's foot."""
    a, ab = polyline[:-1], np.diff(polyline, axis=0)
    t = np.clip(np.einsum("pij,ij->pi", points[:, None] - a[None], ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    distance = np.linalg.norm(points[:, None] - (a[None] + t[..., None] * ab[None]), axis=2)
    k = np.argmin(distance, axis=1)
    rows = np.arange(len(points))
    return distance[rows, k], k, t[rows, k]


def _arc(points: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def compare_with_vmtk(ours: np.ndarray, our_radius: np.ndarray, vmtk: np.ndarray, vmtk_radius: np.ndarray):
    """Mean and max distance (mm) and median |relative radius difference|, away from both paths' end radii."""
    distance, k, t = _foot(ours, vmtk)
    their_radius = vmtk_radius[k] * (1 - t) + vmtk_radius[k + 1] * t
    s, s_vmtk = _arc(ours), _arc(vmtk)
    foot = s_vmtk[k] + t * (s_vmtk[k + 1] - s_vmtk[k])
    keep = (s > our_radius[0]) & (s < s[-1] - our_radius[-1])
    keep &= (foot > vmtk_radius[0]) & (foot < s_vmtk[-1] - vmtk_radius[-1])
    relative = np.abs(our_radius - their_radius) / their_radius
    return float(distance[keep].mean()), float(distance[keep].max()), float(np.median(relative[keep])), int(keep.sum())


@pytest.mark.parametrize("surface", ["aorta-surface-open-ends.stl", "aorta-surface.stl"])
def test_centerlines_match_vmtk(aorta_dir, surface):
    vertices, faces = read_surface(aorta_dir / surface)
    result = extract_centerlines(vertices, faces)
    reference = [_distinct(p.points, p.radius) for p in read_centerline_network(aorta_dir / "aorta-centerline.vtp")
                 .polylines]
    assert len(result.paths) == 2
    matched = set()
    for points, radius in zip(result.paths, result.radii, strict=True):
        # VMTK's path to the same iliac: the one whose distal end is nearest ours
        j = int(np.argmin([np.linalg.norm(ref[0][-1] - points[-1]) for ref in reference]))
        matched.add(j)
        mean, worst, radius_diff, compared = compare_with_vmtk(points, radius, *reference[j])
        assert compared > 100
        assert mean <= MEAN_TOL_MM and worst <= MAX_TOL_MM and radius_diff <= RADIUS_MEDIAN_RTOL, (
            f"{surface} path to VMTK's {j}: mean {mean:.3f} mm, max {worst:.3f} mm, radius {100 * radius_diff:.2f} %")
    assert matched == {0, 1}  # one path to each iliac
    # the inlet is the aorta (the wide end, high y), not an iliac
    assert all(p[0, 1] > 165.0 for p in result.paths)


def _path_length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


#: Issue 29's targets: each end within 1 mm of VMTK's, the length within 2 % of VMTK's.
END_TOL_MM, LENGTH_RTOL = 1.0, 0.02


def test_open_surface_paths_reach_the_openings_as_vmtk_does(aorta_dir):
    """Measured (issue 29): lengths 77.59 and 79.38 mm against VMTK's 76.16 and 77.81 (+1.9 %, +2.0 %), outlets
    0.97 and 0.73 mm from VMTK's ends, inlets 2.28 and 2.24 mm (before: 66.34 and 68.15 mm, 4.3 and 5.1 mm).

    VMTK's paths were computed on a surface clipped 2.08 mm deeper at the inlet than this one (its inlet
    point lies that far inside this surface's inlet opening, measured here), so the inlet is compared
    after that depth, and the length against VMTK's plus it.
    """
    from softdesign.centerline.closing import boundary_loops

    vertices, faces = read_surface(aorta_dir / "aorta-surface-open-ends.stl")
    result = extract_centerlines(vertices, faces)
    reference = [p.points for p in read_centerline_network(aorta_dir / "aorta-centerline.vtp").polylines]
    loop = max(boundary_loops(faces), key=len)  # the aorta's (the inlet's) rim
    centre = vertices[loop].mean(axis=0)
    normal = np.linalg.svd(vertices[loop] - centre)[2][-1]
    depth = abs(float((reference[0][0] - centre) @ normal))  # VMTK's inlet below this opening's plane
    assert 1.5 < depth < 2.5
    for k, points in enumerate(result.paths):
        vmtk = min(reference, key=lambda r: float(np.linalg.norm(r[-1] - points[-1])))
        assert result.short_mm[k] == (0.0, 0.0)  # both ends at their openings' centres
        assert float(np.linalg.norm(points[-1] - vmtk[-1])) <= END_TOL_MM
        inlet_gap = float(np.linalg.norm(points[0] - vmtk[0]))
        assert inlet_gap <= END_TOL_MM + depth, inlet_gap
        expected = _path_length(vmtk) + depth
        assert abs(_path_length(points) - expected) <= LENGTH_RTOL * _path_length(vmtk), (
            _path_length(points), expected)


def test_capped_surface_paths_continue_to_the_rounded_ends(aorta_dir):
    """The capped aorta's caps are domes (no flat face, no labels): each end is continued to the centre of the
    sphere touching the dome's tip, where the medial axis of a rounded end stops.  Measured (issue 29): 74.42
    and 72.35 mm against VMTK's 77.81 and 76.16 (-4.4 %, -5.0 %; before: 66.61 and 64.80, -14.4 %, -14.9 %);
    ends 1.64 to 1.69 mm from VMTK's (before: 4.5 to 6.3 mm).

    Issue 29's 1 mm / 2 % target is not met here, and no rule that finds this surface's own ends can meet it:
    the capped surface runs 3.3 to 3.8 mm past the open surface's openings (measured below), near which
    VMTK's ends lie, so its domes' bases are about 2 mm beyond VMTK's ends and the medial axis's ends about
    1.5 mm short of them.
    """
    from softdesign.centerline.closing import boundary_loops

    open_vertices, open_faces = read_surface(aorta_dir / "aorta-surface-open-ends.stl")
    vertices, faces = read_surface(aorta_dir / "aorta-surface.stl")
    result = extract_centerlines(vertices, faces)
    reference = [p.points for p in read_centerline_network(aorta_dir / "aorta-centerline.vtp").polylines]
    for k, points in enumerate(result.paths):
        vmtk = min(reference, key=lambda r: float(np.linalg.norm(r[-1] - points[-1])))
        assert min(result.continued_mm[k]) > 2.0  # both rounded ends were continued
        for ours, theirs in ((points[0], vmtk[0]), (points[-1], vmtk[-1])):
            assert float(np.linalg.norm(ours - theirs)) <= 2.0 * END_TOL_MM
        assert abs(_path_length(points) / _path_length(vmtk) - 1.0) <= 3.0 * LENGTH_RTOL
    middle = open_vertices.mean(axis=0)
    for loop in boundary_loops(open_faces):
        rim = open_vertices[loop]
        centre = rim.mean(axis=0)
        normal = np.linalg.svd(rim - centre)[2][-1]
        normal *= np.sign((centre - middle) @ normal)  # outwards
        along = (vertices - centre) @ normal
        beside = np.linalg.norm(vertices - centre - along[:, None] * normal, axis=1) < 1.2 * np.sqrt(
            np.mean(np.sum((rim - centre) ** 2, axis=1)))
        assert 3.0 < along[beside].max() < 4.0  # how far the capped surface runs past this opening, mm
