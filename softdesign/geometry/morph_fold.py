"""Does the morph fold?  The reach r(l) * kappa(q, l) of every blended shape, before any fit.

A tube of radius rho around a centerline of curvature kappa folds through
itself where ``rho * kappa >= 1`` (:mod:`softdesign.fitting.radius_field`).
The fit is not needed to see most folds coming: the wall's radius is at
least about the vessel's ``MaximumInscribedSphereRadius`` r(l) (the largest
sphere inside the wall), and rho(q) blends the fitted wall with its own
around-the-axis mean, so ``r(l) * kappa(q, l)`` is a lower bound of the
reach of every shape c(q, .), known from the centerlines alone.

Two failures show in it, each with its own cause and fix:

* the **blend** folds: the end shapes are clear but an intermediate shape
  is not.  The seed's linear blend c(q) = (1 - q) c0 + q cf of a straight
  line and a curve that turns back on itself (a U-turn, a hook) is shorter
  than both in the middle and kinks there; the intrinsic blend interpolates
  the curvature vector, so its curvature never exceeds the larger of the
  end shapes' at the same l, and with it the morph folds only where an end
  shape does.
* the **centerline** folds: the q = 1 shape itself turns tighter than the
  vessel is wide (a VMTK centerline at a wide bifurcation).  No blend and
  no fit can avoid it.

The check samples q on a grid of ``MORPH_Q_SAMPLES`` values (every 0.025,
so exported q values are not the only ones looked at) and refines the worst
one by a bounded search; l is the curve's dense grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.optimize import minimize_scalar

from softdesign.geometry.blend import BlendedShape
from softdesign.types import FloatArray

#: q samples of the sweep (then a bounded refinement around the worst).
MORPH_Q_SAMPLES = 41


def morph_q_grid() -> FloatArray:
    """The sweep's q values (MORPH_Q_SAMPLES,): ``i / (n - 1)``, each a correctly rounded quotient, so an export q
    ``j / (m - 1)`` (``export.frames``) on the same rational is the same double and its curves, built once by the
    kinematics, are found again (``np.linspace``'s ``i * step`` differs in the last bit for 15 of 41 values)."""
    return np.arange(MORPH_Q_SAMPLES) / (MORPH_Q_SAMPLES - 1)
#: The reach r * kappa, with r the inscribed radius, at which a shape is taken to fold.  The wall's
#: rho exceeds r on an elliptical section (on the VMTK aorta, up to 1.8 r at the inlet), so a
#: reach of 0.8 of the inscribed radius already leaves rho * kappa little room below 1.
MORPH_REACH_LIMIT = 0.8


@dataclass(frozen=True)
class MorphReach:
    """The largest r(l) * kappa(q, l) over the morph and where it is.

    Attributes
    ----------
    reach : dimensionless, r * kappa at the worst place (the tube folds near 1)
    q : where in the morph, in [0, 1]
    l : normalized l of the worst place; ``arc_mm`` the same in mm of the shape at q
    radius_mm : r there, mm; ``curvature_per_mm`` kappa there, 1/mm
    end_reach : the largest reach of the end shapes (q = 0 and q = 1)
    final_reach : the largest reach of the q = 1 shape alone, and ``final_l`` where it is
    """

    reach: float
    q: float
    l: float
    arc_mm: float
    radius_mm: float
    curvature_per_mm: float
    end_reach: float
    final_reach: float
    final_l: float

    @property
    def blend_folds(self) -> bool:
        """An intermediate shape reaches the limit while both end shapes stay below it."""
        return self.reach >= MORPH_REACH_LIMIT > self.end_reach

    @property
    def final_folds(self) -> bool:
        """The q = 1 shape itself reaches the limit: the centerline turns tighter than the vessel is wide."""
        return self.final_reach >= MORPH_REACH_LIMIT

    def as_dict(self) -> dict[str, float]:
        """JSON-ready figures (mm, 1/mm, dimensionless)."""
        return {
            "max_reach": self.reach, "q": self.q, "l": self.l, "arc_mm": self.arc_mm, "radius_mm": self.radius_mm,
            "curvature_per_mm": self.curvature_per_mm, "end_reach": self.end_reach,
            "final_reach": self.final_reach, "final_l": self.final_l, "limit": MORPH_REACH_LIMIT,
        }


def morph_reach(shape: BlendedShape, radius_l: npt.ArrayLike, radius_mm: npt.ArrayLike) -> MorphReach:
    """The largest ``r(l) * kappa(q, l)`` over q in [0, 1] and the dense l grid.

    Parameters
    ----------
    shape : the blended centerlines c(q, l)
    radius_l : (k,) increasing normalized l of the inscribed radii (on the final shape)
    radius_mm : (k,) the inscribed radii there, mm (``np.interp`` between, held at the ends)
    """
    l = shape.keys[-1].dense_l()
    radius = np.interp(l, np.asarray(radius_l, float), np.asarray(radius_mm, float))

    def reach_at(q: float) -> float:
        return float(np.max(radius * shape.smooth_curve_at(q).curvature(l)))

    grid = morph_q_grid()
    values = np.array([reach_at(q) for q in grid])
    best = int(np.argmax(values))
    q_max = float(grid[best])
    if 0 < best < len(grid) - 1:
        found = minimize_scalar(lambda q: -reach_at(q), bounds=(grid[best - 1], grid[best + 1]),
                                method="bounded", options={"xatol": 1e-4})
        if -found.fun > values[best]:
            q_max = float(found.x)
    curve = shape.smooth_curve_at(q_max)
    kappa = curve.curvature(l)
    i = int(np.argmax(radius * kappa))
    final = radius * shape.smooth_curve_at(1.0).curvature(l)
    j = int(np.argmax(final))
    return MorphReach(
        reach=float(radius[i] * kappa[i]), q=q_max, l=float(l[i]), arc_mm=float(curve.arc_length([l[i]])[0]),
        radius_mm=float(radius[i]), curvature_per_mm=float(kappa[i]), end_reach=float(max(values[0], values[-1])),
        final_reach=float(final[j]), final_l=float(l[j]),
    )


def radius_profile_on(l: FloatArray, radius: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The profile sorted by l, for :func:`morph_reach` (a VMTK path's foot points are almost always in order)."""
    order = np.argsort(l, kind="stable")
    return np.asarray(l, float)[order], np.asarray(radius, float)[order]
