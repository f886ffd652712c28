"""Which end of a path is the inlet, from the geometry: the clearly wider end.

A VMTK network seeded at an outlet (the seed is wherever the user clicked)
shares its first point among all paths, so "the end shared with other
paths" then names an outlet, and a path runs outlet -> bifurcation ->
trunk.  The inlet of a vessel tree is its widest end: when one end's
``MaximumInscribedSphereRadius``, averaged over the ``END_SPAN_FRACTION`` of
the path at that end (a single end point's radius drops at a cap), exceeds the other
end's by ``INLET_RATIO`` or more, that end is the inlet.  Ends of about the
same width leave the choice to the other rules (the shared end, the file's
order) and ``final.inlet``.
"""

from __future__ import annotations

import numpy as np

from softdesign.types import FloatArray, Points

#: One end is clearly the wider when its mean inscribed radius is at least this multiple of the other's.
INLET_RATIO = 1.2
#: The share of the path's length over which each end's inscribed radius is averaged.
END_SPAN_FRACTION = 0.1


def end_radii(points: Points, radius: FloatArray) -> tuple[float, float]:
    """Mean inscribed radius over the first and over the last ``END_SPAN_FRACTION`` of the path, mm."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    span = END_SPAN_FRACTION * s[-1]
    return float(np.mean(radius[s <= span])), float(np.mean(radius[s >= s[-1] - span]))


def widest_end_flip(points: Points, radius: FloatArray | None) -> tuple[bool, str] | None:
    """(reverse the path?, why) when one end is clearly the wider; None when neither is (or no radii)."""
    if radius is None or len(radius) != len(points):
        return None
    first, last = end_radii(points, radius)
    if max(first, last) < INLET_RATIO * min(first, last):
        return None
    wide, narrow = max(first, last), min(first, last)
    return last > first, (
        f"l = 0 at the widest end (the inlet): mean inscribed radius {wide:.3g} mm over the {END_SPAN_FRACTION:.0%} "
        f"of the path at that end against {narrow:.3g} mm at the other; give final.inlet to choose"
    )
