"""Whether a bounded least-squares search stands at its optimum, and why the error it leaves is there.

The inverse (:mod:`softdesign.mechanics.inverse`) minimises ``|e(p)|^2 / 2`` over the chamber pressures ``p``
(k,) kPa within ``0 <= p <= p_max``, with ``e`` (3,) mm the weighted arc error.  At an equilibrium ``p`` whose
Jacobian ``J = de/dp`` (3, k) mm/kPa is known, the Gauss-Newton model ``|e + J dp|`` is minimised on the box
``-p <= dp <= p_max - p`` (scipy's ``lsq_linear``: three rows, k columns, no solve).  That model is convex and its
gradient at ``dp = 0`` is the problem's own, ``J^T e``, so its minimum is ``dp = 0`` exactly when ``p`` meets the
first-order (KKT) conditions of the bounded problem: every free pressure's gradient zero, every pressure at a bound
pushed against it.  How much lower the model's minimum is than ``|e|`` measures how far ``p`` is from that:
when it is below ``max(share |e|, tolerance)`` no feasible change of the pressures lowers the error by more, to
first order, and the search has found the best the section does within the bounds.

Assumptions: ``J`` is the exact derivative at ``p`` (the equilibrium's ``du/dp``); the test is first order, so it
holds at any stationary point of the bounded problem (the search's own, which is local like any descent's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray

#: A pressure within this share of the bound's span from a bound counts as on it (scipy's trust-region search keeps
#: its iterates strictly inside the box: measured 2.6e-4 kPa from 0 and 0.012 kPa from 100 on the demo's section;
#: its last trial there stopped at 99.90 kPa, the model's best pressures on the bound).
ON_BOUND_SHARE = 1e-3


@dataclass(frozen=True)
class Stationarity:
    """What the Gauss-Newton model on the bounds says at one point (mm, kPa).

    Attributes
    ----------
    error_mm : |e| at the point
    predicted_mm : the model's least |e + J dp| within the bounds
    held_high : chambers (0-based) on the upper bound whose pressure the error would have higher
    held_low : chambers on 0 whose pressure the error would have lower (a chamber cannot pull)
    """

    error_mm: float
    predicted_mm: float
    held_high: tuple[int, ...]
    held_low: tuple[int, ...]

    def is_optimum(self, share: float, tolerance_mm: float) -> bool:
        """True when no feasible change lowers the error by more than ``max(share |e|, tolerance_mm)``."""
        return self.error_mm - self.predicted_mm <= max(share * self.error_mm, tolerance_mm)


def stationarity(jacobian: FloatArray, error: FloatArray, pressures: FloatArray, max_pressure: float
                 ) -> Stationarity:
    """The model's least error within ``[0, max_pressure]`` from ``pressures`` (k,) kPa, and the bounds that hold.

    ``jacobian`` (3, k) mm/kPa and ``error`` (3,) mm at ``pressures``.  A chamber is held by a bound when the
    model's best pressures put it on that bound (within :data:`ON_BOUND_SHARE` of the span) and the error's
    gradient ``J^T e`` points out of the box there (the error would have it beyond).
    """
    from scipy.optimize import lsq_linear

    J, e, p = np.asarray(jacobian, float), np.asarray(error, float), np.asarray(pressures, float)
    low, high = -p, max_pressure - p
    found = lsq_linear(J, -e, bounds=(low, high), method="bvls")
    gradient, best = J.T @ e, p + found.x
    near = ON_BOUND_SHARE * max_pressure
    held_high = tuple(int(c) for c in np.flatnonzero((best >= max_pressure - near) & (gradient < 0)))
    held_low = tuple(int(c) for c in np.flatnonzero((best <= near) & (gradient > 0)))
    return Stationarity(float(np.linalg.norm(e)), float(np.linalg.norm(e + J @ found.x)), held_high, held_low)


def _chambers(indices: tuple[int, ...]) -> str:
    names = [str(c + 1) for c in indices]
    return ("chamber " if len(names) == 1 else "chambers ") + (", ".join(names[:-1]) + " and " if len(names) > 1
                                                               else "") + names[-1]


def why_left(s: Stationarity, max_pressure: float, error: FloatArray, reached: tuple[float, float, float],
             target: tuple[float, float, float], length_rates: FloatArray) -> str:
    """Why the error stays (a sentence): the bounds that hold the pressures and the error's bend and length parts.

    ``error`` (3,) mm the weighted error ([bend x, bend y, length]); ``reached`` and ``target`` the arcs (kappa 1/mm,
    phi rad, L mm); ``length_rates`` (k,) mm/kPa ``dL/dp`` of each chamber (the Jacobian's length row).
    """
    parts = []
    if s.held_high:
        parts.append(f"{_chambers(s.held_high)} at the pressure bound {max_pressure:g} kPa (--max-pressure, "
                     "simulate.max_pressure_kpa), which the error would have higher")
    if s.held_low:
        parts.append(f"{_chambers(s.held_low)} at 0 kPa, which the error would have lower (a chamber cannot pull)")
    bend, length = float(np.hypot(error[0], error[1])), float(abs(error[2]))
    text = "; ".join(parts) + ("; " if parts else "") + (
        f"the error left: {bend:.3g} mm of bend (curvature {reached[0]:.4g} 1/mm, the target's {target[0]:.4g}) "
        f"and {length:.3g} mm of length ({reached[2]:.4f} mm, the target's {target[2]:.4f} mm)")
    if reached[2] > target[2] and np.all(np.asarray(length_rates) > 0):
        text += ("; every chamber's pressure lengthens the section (dL/dp > 0 at these pressures), which is "
                 "already longer than the target")
    return text
