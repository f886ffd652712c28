"""Continuation in the cavities' volume: a pressure path followed past its limit point, and the limit located.

Why volume control
    A pressurised chamber's pressure-volume curve has a maximum (an
    unreinforced chamber balloons): beyond it no pressure is higher, and load
    stepping, which asks for a pressure, fails near it and cannot say whether
    the failure is the limit or the solver.  The volume keeps growing through
    the limit, so it is the natural control (a syringe pump sets it, not the
    pressure).  With the pressures ``t p`` in a fixed pattern ``p``, the
    load's work-conjugate of ``t`` is ``c . u`` with ``c = f_p(u; p)`` the
    pressure forces of the pattern, ``dV/du`` weighted by ``p`` (the
    pressure-weighted cavity volume's change, to first order).  Each step
    prescribes ``c_n . (u - u_n) = dw`` (``c_n`` at the step's start): the
    linearized volume control of the arc-length family (Riks; de Borst's
    indirect displacement control), solved for ``(u, t)`` by a bordered
    Newton method with the problem's own factorization::

        K a = -R,  K b = f_p,  dt = -(g + c . a) / (c . b),  du = a + dt b,

    ``g = c . (u - u_n) - dw``.  It works for any pattern, several cavities
    and the reinforcement's fibres included.
The limit point
    The path's slope ``dt/dw = 1 / (c . K^-1 c)`` is positive on the rising
    branch, passes through zero at the limit (``K`` singular) and is negative
    beyond it.  When a step ends with a negative slope (or a lower t), the
    limit is bracketed; secant steps on the slope shrink the bracket until
    the two tangent lines' crossing (an upper bound of a concave t(w)) is
    within ``limit_rtol`` of the higher equilibrium found (a lower bound),
    and the bracket's width in w within ``limit_rtol`` of the work done (a
    flat maximum's t is found long before where it is).
    The limit reported is that equilibrium, with the bound.
Ending
    Reaching ``t = 1`` (the last step is load-controlled to land on it
    exactly), a limit point below it, or a step that fails after every
    halving: each is stated with the largest load factor reached.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from softdesign.mechanics.assembly import InvertedElementError
from softdesign.mechanics.linear_solve import TangentSolver
from softdesign.mechanics.newton import (
    NewtonSettings,
    PressureProblem,
    SolveRecord,
    _newton_step,
    _residual,
    check_admissible,
    pressure_forces,
    tangent_solver,
)
from softdesign.mechanics.quadratic import QuadraticMesh, linearized_pressure
from softdesign.types import FloatArray


@dataclass(frozen=True)
class ContinuationSettings:
    """How the path is stepped and when a limit point counts as found.

    Attributes
    ----------
    first_step : the first step's load factor on the initial tangent (0 < . <= 1)
    max_steps : converged steps allowed (>= 1)
    max_cutbacks : step halvings allowed over the whole path
    limit_rtol : the limit's load factor is bracketed within this share of it
    max_refinements : secant steps allowed to locate a limit
    newton : Newton's iterations and tolerances per step
    """

    first_step: float = 0.25
    max_steps: int = 200
    max_cutbacks: int = 12
    limit_rtol: float = 1e-3
    max_refinements: int = 30
    newton: NewtonSettings = field(default_factory=NewtonSettings)


@dataclass(frozen=True)
class PathPoint:
    """A converged equilibrium on the path: displacement (V, 3) mm, load factor, slope dt/dw (1/(mN mm)), and the
    residuals (mN) of the Newton iterations that found it."""

    u: FloatArray
    t: float
    slope: float
    history: tuple[float, ...] = ()


@dataclass(frozen=True)
class PathResult:
    """Where the path ended.

    Attributes
    ----------
    status : ``reached`` (t = 1), ``limit`` (a limit point below 1) or ``stopped`` (a step failed)
    end : the last equilibrium (at t = 1, at the limit, or the highest reached)
    load_factor : its t; the pressures are ``t p``
    limit_upper : at a limit, the upper bound of its t (NaN otherwise)
    path : (n, 2) load factor and the cumulative work ``sum c_n . du`` (mN mm) of every converged point
    steps : the converged points after the start, in order (their load factors and Newton residuals)
    """

    status: str
    end: PathPoint
    load_factor: float
    limit_upper: float
    path: FloatArray
    steps: tuple[PathPoint, ...] = ()

    def record(self) -> SolveRecord:
        """The path as a solve's record: per converged point its load factor, iterations and residuals."""
        record = SolveRecord()
        for point in self.steps:
            record.load_factors.append(point.t)
            record.iterations.append(len(point.history))
            record.residuals.append(list(point.history))
        return record

    def stopped_because(self, pressures: FloatArray) -> str:
        """Why the path ended below the pressures (k,) kPa, with the largest load it reached."""
        reached = ", ".join(f"{self.load_factor * p:.4g}" for p in pressures)
        if self.status == "limit":
            upper = ", ".join(f"{self.limit_upper * p:.4g}" for p in pressures)
            return (f"no equilibrium at {', '.join(f'{p:g}' for p in pressures)} kPa: the pressures reach a limit "
                    f"point at {reached} kPa (load factor {self.load_factor:.5g}; the true limit is below {upper} "
                    "kPa), where the chamber balloons: lower the pressures, or reinforce the chambers")
        return (f"the solve stopped at {reached} kPa (load factor {self.load_factor:.4g}, the largest it reached "
                f"towards {', '.join(f'{p:g}' for p in pressures)} kPa): no step converged beyond it after every "
                "halving; refine the mesh or lower the pressures")


class _Path:
    """The bordered Newton steps of one problem and pressure pattern."""

    def __init__(self, problem: PressureProblem, pattern: FloatArray, settings: ContinuationSettings,
                 solver: TangentSolver) -> None:
        self.problem, self.pattern, self.settings, self.solver = problem, pattern, settings, solver
        self.free = ~problem.fixed

    def load(self, u: FloatArray) -> FloatArray:
        """The pattern's pressure forces (3V,) mN at ``u`` (``c``)."""
        return pressure_forces(self.problem, self.problem.mesh.points + u, self.pattern, False)[0]

    def slope(self, u: FloatArray, t: float) -> float:
        """``dt/dw = 1 / (c . K^-1 c)`` at an equilibrium."""
        _, _, K, _ = _residual(self.problem, u, t * self.pattern, True)
        assert K is not None
        c = self.load(u)
        return 1.0 / float(c @ tangent_solver(K, self.free, self.solver)(c))

    def step(self, start: PathPoint, dw: float, guess: tuple[FloatArray, float]) -> PathPoint | None:
        """The equilibrium with ``c . (u - u_start) = dw``, from ``guess``; None if Newton fails."""
        c, (u, t) = self.load(start.u), guess
        newton, problem, pressure, history = self.settings.newton, self.problem, None, []
        for _ in range(newton.max_iterations):
            try:
                R, f_p, K, state = _residual(problem, u, t * self.pattern, True, pressure)
            except InvertedElementError:
                return None
            g = float(c @ (u - start.u).ravel()) - dw
            scale = float(np.linalg.norm(self.load(u)[self.free])) * max(abs(t), 1e-12)
            history.append(float(np.linalg.norm(R[self.free])))
            if history[-1] <= newton.rtol * scale + newton.atol and abs(g) <= newton.rtol * abs(dw):
                return PathPoint(u, t, self.slope(u, t), tuple(history))
            if K is None:
                return None
            solve = tangent_solver(K, self.free, self.solver)
            a, b = solve(-R), solve(self.load(u))
            dt = -(g + c @ a) / (c @ b)
            du = (a + dt * b).reshape(-1, 3)
            if not np.all(np.isfinite(du)):
                return None
            new_u, share = _admissible_share(problem, u, du)
            if state is not None:
                assert isinstance(problem.mesh, QuadraticMesh)
                pressure = linearized_pressure(problem.mesh, problem.law, state, new_u - u)
            u, t = new_u, t + share * float(dt)
        return None


def _admissible_share(problem: PressureProblem, u: FloatArray, du: FloatArray) -> tuple[FloatArray, float]:
    """``u + s du`` with the largest ``s`` of 1, 1/2, ... 1/16 that inverts no element, and s."""
    for k in range(5):
        try:
            check_admissible(problem, u + du / 2**k)
        except InvertedElementError:
            continue
        return u + du / 2**k, 1.0 / 2**k
    return u + du, 1.0


def follow_pressures(problem: PressureProblem, pressures: FloatArray, settings: ContinuationSettings,
                     solver: TangentSolver | None = None,
                     on_step: Callable[[PathPoint], None] | None = None) -> PathResult:
    """Follow the pressures ``t pressures`` (k,) kPa from t = 0 towards 1 in volume steps (the module's docstring).

    ``on_step`` is told of every converged point on the way (a progress display).
    """
    pattern = np.asarray(pressures, float)
    if not np.any(pattern):  # no load: the rest state
        rest = PathPoint(np.zeros_like(problem.mesh.points), 1.0, float("inf"))
        return PathResult("reached", rest, 1.0, float("nan"), np.array([[0.0, 0.0], [1.0, 0.0]]), (rest,))
    path = _Path(problem, pattern, settings, TangentSolver() if solver is None else solver)
    start = PathPoint(np.zeros_like(problem.mesh.points), 0.0, path.slope(np.zeros_like(problem.mesh.points), 0.0))
    dw, cutbacks = settings.first_step / start.slope, 0
    points, works, previous = [start], [0.0], None
    for _ in range(settings.max_steps):
        guess = _predictor(start, previous, dw)
        new = path.step(start, dw, guess)
        if new is None:
            if cutbacks >= settings.max_cutbacks:
                return _ended("stopped", max(points, key=lambda p: p.t), points, works)
            cutbacks, dw = cutbacks + 1, dw / 2
            continue
        if new.t >= 1.0 and new.slope > 0 or (new.t >= 1.0 and start.slope > 0):
            # the last step lands on t = 1 from the path's chord between the two equilibria that bracket it
            share = (1.0 - start.t) / (new.t - start.t)
            u, history = _newton_step(problem, start.u + share * (new.u - start.u), pattern, settings.newton,
                                      path.solver)
            if u is not None:
                end = PathPoint(u, 1.0, path.slope(u, 1.0), tuple(history))
                return _ended("reached", end, [*points, end], [*works, works[-1] + dw])
        if new.slope < 0 or new.t < start.t:
            return _limit(path, start, new, dw, points, works)
        points.append(new)
        works.append(works[-1] + dw)
        if on_step is not None:
            on_step(new)
        previous, start = (start, dw), new
        dw *= 1.5
    return _ended("stopped", max(points, key=lambda p: p.t), points, works)


def _predictor(start: PathPoint, previous: tuple[PathPoint, float] | None, dw: float) -> tuple[FloatArray, float]:
    """The secant through the last two points, scaled to ``dw`` (the start itself at the first step)."""
    if previous is None:
        return start.u, start.t
    before, dw_before = previous
    share = dw / dw_before
    return start.u + share * (start.u - before.u), start.t + share * (start.t - before.t)


def _limit(path: _Path, low: PathPoint, high: PathPoint, dw: float, points: list[PathPoint],
           works: list[float]) -> PathResult:
    """Shrink the bracket [low (rising), high (past the limit)] by secant steps on the slope (module docstring)."""
    span = dw
    for _ in range(path.settings.max_refinements):
        best = max(low, high, key=lambda p: p.t)
        upper = _crossing(low, high, span)
        if upper - best.t <= path.settings.limit_rtol * best.t and span <= path.settings.limit_rtol * works[-1]:
            return _ended("limit", best, [*points, best], [*works, works[-1] + span], upper)
        share = float(np.clip(low.slope / (low.slope - high.slope), 0.1, 0.9))
        trial = path.step(low, share * span, (low.u + share * (high.u - low.u), low.t + share * (high.t - low.t)))
        if trial is None:
            break
        if trial.slope > 0 and trial.t >= low.t:
            span = float(path.load(trial.u) @ (high.u - trial.u).ravel())
            points, works, low = [*points, trial], [*works, works[-1] + share * span], trial
        else:
            high, span = trial, share * span
    best = max(low, high, key=lambda p: p.t)
    return _ended("limit", best, [*points, best], [*works, works[-1]], _crossing(low, high, span))


def _crossing(low: PathPoint, high: PathPoint, span: float) -> float:
    """The load factor where the tangent lines at ``low`` (w = 0) and ``high`` (w = span) cross."""
    if low.slope <= high.slope:
        return max(low.t, high.t)
    w = (high.t - low.t - high.slope * span) / (low.slope - high.slope)
    return low.t + low.slope * float(np.clip(w, 0.0, span))


def _ended(status: str, end: PathPoint, points: list[PathPoint], works: list[float],
           upper: float = float("nan")) -> PathResult:
    path = np.column_stack([[p.t for p in points], works[:len(points)]])
    return PathResult(status, end, end.t, upper, path, tuple(points[1:]))
