"""Hold an end whose fitted radius went to zero or below (issue 29, item 0).

Near a path's end the kept wall points can lean inwards (a tilted cap's rim,
another branch's wall at a one-sided end) so that the fitted rho(l, a) runs
to zero or below there, although the end prior
(:mod:`softdesign.fitting.end_prior`) holds the cells that have no points.
Such a body is never reported as a success, nor refused without a cause: the
end is held, as the end prior holds empty sectors.  :func:`negative_end`
finds the end and the stretch from it to one knot interval past the last
ring whose smallest rho is <= 0 or still below ``RECOVERED_FRACTION`` of the
path's median ring (the points leaning in); the fit drops its kept points there and
fits again, so the end prior holds every cell of the stretch at the inscribed
radius.  A stretch longer than ``MAX_HOLD_FRACTION`` of the path, or a ring
<= 0 away from both ends, is left to the fold check's refusal, which names
the place and the cause.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.types import FloatArray

#: The most of a path an end hold may take (the fit's end margin is bounded alike).
MAX_HOLD_FRACTION = 0.25
#: A ring is plausible again past the end once its smallest rho is this fraction of the path's median ring.
RECOVERED_FRACTION = 0.5
#: Ring spacing of the search, mm, and angles per angular knot interval.
HOLD_SPACING_MM = 0.1
HOLD_ANGLES_PER_INTERVAL = 8


@dataclass(frozen=True)
class EndHold:
    """The end held: ``end`` ("inlet" or "outlet"), its stretch in normalized l, what rho reached and where."""

    end: str
    from_l: float
    to_l: float
    rho_min_mm: float
    at_l: float

    def keeps(self, l: FloatArray) -> np.ndarray:
        """(n,) bool: the points outside the held stretch."""
        l = np.asarray(l, float)
        return (l > self.to_l) if self.end == "inlet" else (l < self.from_l)

    def as_dict(self, length_mm: float) -> dict[str, float]:
        """JSON-ready, mm along the path."""
        return {"from_mm": self.from_l * length_mm, "to_mm": self.to_l * length_mm,
                "held_mm": (self.to_l - self.from_l) * length_mm, "rho_min_mm": self.rho_min_mm,
                "at_mm": self.at_l * length_mm}


def negative_end(spline: RadiusSpline, length_mm: float, knot_spacing_mm: float) -> EndHold | None:
    """The end to hold where the fitted rho <= 0 near it, or None (rho > 0 everywhere, or not at an end).

    Parameters
    ----------
    spline : the fitted rho(l, a) over the whole path
    length_mm : the path's length, mm
    knot_spacing_mm : the fit's knot interval, mm (the stretch runs one interval past the last ring <= 0)
    """
    l = np.linspace(0.0, 1.0, max(int(np.ceil(length_mm / HOLD_SPACING_MM)), 16) + 1)
    a = np.linspace(0.0, 2.0 * np.pi, HOLD_ANGLES_PER_INTERVAL * spline.angular_intervals, endpoint=False)
    ring = spline.evaluate_grid(l, a).min(axis=1)
    low = ring <= 0.0
    if not low.any():
        return None
    worst = int(np.argmin(ring))
    margin = knot_spacing_mm / length_mm
    inlet, outlet = low & (l <= 0.5), low & (l > 0.5)
    # the stretch runs on until the rings are plausible again (the wall points leaning in lie there)
    thin = ring < RECOVERED_FRACTION * float(np.median(ring))
    if l[worst] <= 0.5:
        last = int(np.flatnonzero(inlet).max())
        while last + 1 < len(l) and thin[last + 1]:
            last += 1
        hold = EndHold("inlet", 0.0, min(1.0, float(l[last]) + margin), float(ring[worst]), float(l[worst]))
    else:
        first = int(np.flatnonzero(outlet).min())
        while first > 0 and thin[first - 1]:
            first -= 1
        hold = EndHold("outlet", max(0.0, float(l[first]) - margin), 1.0, float(ring[worst]), float(l[worst]))
    if hold.to_l - hold.from_l > MAX_HOLD_FRACTION or (inlet.any() and outlet.any()):
        return None
    return hold
