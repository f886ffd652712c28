"""The project's sample vessel (data/demo): its surface was generated around a known centerline.

The sample's main vessel is elliptical (semi-axes r(1 + e) and r(1 - e), e = 0.08): the medial axis of an
elliptical section is a segment along the major axis of half-length a - b^2 / a (about 1 mm here), on
which the inscribed radius is nearly constant, so a least-cost path may wander along it (VMTK's too).
"""

from __future__ import annotations

import numpy as np

from softdesign.centerline.extract import extract_centerlines
from softdesign.io.centerline import read_centerline_network
from softdesign.io.surface import read_surface
from tests.centerline.test_centerline_vmtk import RADIUS_MEDIAN_RTOL, _distinct, compare_with_vmtk
from tests.helpers.paths import REPO

#: Max distance to the generating centerline: issue 18's max target; mean: measured 0.11 mm, allowed 0.15 mm,
#: a sixth of the medial segment's half-length the ellipticity leaves the path free to wander along.
MEAN_TOL_MM, MAX_TOL_MM = 0.15, 0.5


def test_main_vessel_follows_the_generating_centerline():
    vertices, faces = read_surface(REPO / "data" / "demo" / "surface.stl")
    result = extract_centerlines(vertices, faces)
    assert result.endpoints == "planar caps" and len(result.paths) == 2
    main = read_centerline_network(REPO / "data" / "demo" / "centerline.vtp").polylines[0]
    # the path to the main vessel's distal cap (0, 0, 90) is the one ending nearest it
    k = int(np.argmin([np.linalg.norm(p[-1] - [0.0, 0.0, 90.0]) for p in result.paths]))
    mean, worst, radius_diff, compared = compare_with_vmtk(
        result.paths[k], result.radii[k], *_distinct(main.points, main.radius))
    assert compared > 200
    assert mean <= MEAN_TOL_MM and worst <= MAX_TOL_MM and radius_diff <= RADIUS_MEDIAN_RTOL, (mean, worst, radius_diff)
