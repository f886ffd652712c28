"""Does the fitted body fold anywhere in the morph?  ``1 - rho(q) * kappa_n(q) > 0`` at every q searched.

The fit checks the q = 1 body (:func:`softdesign.fitting.radius_field.check_self_folding`)
and the export each exported q; between them a body can fold where no mesh
is made, or where one will be.  :func:`fold_over_morph` evaluates the tube
map's Jacobian with the fitted radius field, rho(q) = (1 - q) rho0 + q rhof,
on the same q grid as the morph's reach search before the fit
(:data:`softdesign.geometry.morph_fold.MORPH_Q_SAMPLES` values, passed in),
then refines the worst q by a bounded search between its neighbours.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar

from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.fitting.radius_field import FoldReport, RadiusField, fold_margin
from softdesign.types import FramedCurve

#: The bounded refinement stops at this width in q.
Q_XTOL = 1e-3


@dataclass(frozen=True)
class MorphFold:
    """The largest rho(q) * kappa_n(q) over the morph: where (q, l, mm, angle) and how many q were looked at."""

    q: float
    report: FoldReport
    samples: int

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (rad for the angle, mm along the shape at q)."""
        r = self.report
        return {"max_rho_kappa": r.max_rho_kappa, "q": self.q, "l": r.l, "arc_mm": r.arc_mm, "angle": r.angle,
                "min_rho_mm": r.min_rho_mm, "q_samples": self.samples}

    def warning(self, mode: str = "linear") -> str | None:
        """A line when the body folds before q = 1 (q = 1 itself is refused by the fit), else None.

        ``mode`` is the blend built: intrinsic is offered only when it is not the one in use.
        """
        r = self.report
        if r.max_rho_kappa < 1.0 or self.q >= 1.0:
            return None
        fix = ("hold the body thinner (fit.max_radius_mm, or fit.local_max_radius over the stretch)" if mode != "linear"
               else "blend: intrinsic keeps the curvature within the end shapes', or hold the body thinner "
                    "(fit.max_radius_mm)")
        return (f"the fitted body folds mid-morph: at q = {self.q:.3f}, l = {r.l:.4f} ({r.arc_mm:.1f} mm from the "
                f"inlet), angle {np.degrees(r.angle):.0f} deg, rho * kappa = {r.max_rho_kappa:.3f} (folds at 1): "
                f"meshes at export q near it will fail; {fix}")


def fold_over_morph(shape_at: Callable[[float], FramedCurve], field: RadiusField, q_grid: np.ndarray,
                    mapper: Mapper = serial_map, built: Callable[[float], FramedCurve | None] | None = None
                    ) -> MorphFold:
    """The largest ``rho(q) * kappa_n(q)`` over ``q_grid`` (increasing, in [0, 1]), refined around the worst.

    Parameters
    ----------
    shape_at : q -> the framed centerline c(q, .)
    field : the fitted radius field
    q_grid : (k,) the q values searched first
    mapper : runs the grid's q values (each its own), perhaps on other processes; the same figures for any
    built : q -> the curve ``shape_at(q)`` returns if it is built already here, else None (then not built): the
        grid's reports around those curves are kept on ``field`` (:meth:`RadiusField.keep_fold`), for a later
        stage that asks for them again (the feasibility's per export q); None keeps none
    """
    task, items = morph_grid(shape_at, field, q_grid)
    return fold_over_morph_from(shape_at, field, q_grid, mapper(task, items), built)


def morph_grid(shape_at: Callable[[float], FramedCurve], field: RadiusField, q_grid: np.ndarray
               ) -> tuple[Callable[[float], FoldReport], list[float]]:
    """:func:`fold_over_morph`'s grid as a task and its items (the q values, each its own), for a caller that runs
    them in a call of its mapper with other work; their reports, in order, go to :func:`fold_over_morph_from`."""
    return (lambda q: fold_margin(shape_at(float(q)), field, float(q))), np.asarray(q_grid, float).tolist()


def fold_over_morph_from(shape_at: Callable[[float], FramedCurve], field: RadiusField, q_grid: np.ndarray,
                         reports: list[FoldReport], built: Callable[[float], FramedCurve | None] | None = None
                         ) -> MorphFold:
    """:func:`fold_over_morph` given the grid's ``reports`` (:func:`morph_grid`'s task on each of its items)."""
    q_grid = np.asarray(q_grid, float)
    for q, r in zip(q_grid.tolist(), reports, strict=True):
        curve = None if built is None else built(q)
        if curve is not None:
            field.keep_fold(curve, q, r)
    best = int(np.argmax([r.max_rho_kappa for r in reports]))
    q, report = float(q_grid[best]), reports[best]
    if 0 < best < len(q_grid) - 1:
        found = minimize_scalar(lambda t: -fold_margin(shape_at(float(t)), field, float(t)).max_rho_kappa,
                                bounds=(q_grid[best - 1], q_grid[best + 1]), method="bounded",
                                options={"xatol": Q_XTOL})
        if -found.fun > report.max_rho_kappa:
            q = float(found.x)
            report = fold_margin(shape_at(q), field, q)
    return MorphFold(q, report, len(q_grid))
