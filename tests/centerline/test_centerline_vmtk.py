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
