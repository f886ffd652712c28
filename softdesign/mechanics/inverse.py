"""The chamber pressures whose deformed section best matches a designed arc: Gauss-Newton on the pressures.

Objective
    The arc is compared through its bending vector ``theta (cos phi, sin phi)``
    (rad; smooth through the straight shape, where phi is undefined) and its
    length L (mm).  The weighted error, in mm, is

        e = [L* / 2 (theta_x - theta_x*), L* / 2 (theta_y - theta_y*), L - L*],

    the first two being, to first order, how far a bending error moves the
    section's tip sideways (an arc of length L turned by d theta about its
    middle), the last how far a length error moves it along: one millimetre of
    either counts the same.
Method
    A bounded trust-region least-squares search (scipy's ``least_squares``, TRF)
    from ``start`` pressures within [0, max_pressure_kpa], ``x_scale`` the
    step size ``max_step_kpa``.  Each evaluation solves the section, continuing
    from the last equilibrium; its Jacobian ``de/dp`` is the equilibrium's exact
    sensitivity ``du/dp`` (:func:`~softdesign.mechanics.newton.pressure_sensitivity`)
    carried through the arc fit by central differences along it.  A trial whose
    solve does not converge (beyond what the chambers hold) counts as a very
    large error, so the trust region shrinks back (the start's must converge).  At most
    ``max_iterations`` evaluations; the result keeps the remaining error, says
    whether it is below ``tolerance_mm``, and gives the Jacobian's singular
    values: an unreinforced chamber balloons rather than lengthens, so the
    common pressure moves L little and the pressures are least determined along (1, 1, 1).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import SolveError
from softdesign.mechanics.newton import NewtonSettings, pressure_sensitivity, solve_pressures
from softdesign.mechanics.reinforcement import HoopThread
from softdesign.mechanics.section import SectionMesh, SectionResult, arc_of, measure_section, prepare_section
from softdesign.types import FloatArray

#: The error (mm, each component) given to the search for a trial whose solve did not converge.
FAILED_TRIAL_MM = 1e6
#: Central-difference step of the arc fit along the sensitivity, as a share of the section's length, 1.
ARC_STEP_SHARE = 1e-4


@dataclass(frozen=True)
class InverseSettings:
    """Bounds and stopping rules of the pressure search (kPa, mm)."""

    max_pressure_kpa: float
    start_kpa: float
    max_step_kpa: float
    tolerance_mm: float = 1e-4
    max_iterations: int = 12
    time_limit_s: float | None = None  #: stop after the trial that passes this many seconds (None: no limit)


@dataclass(frozen=True)
class InverseResult:
    """The pressures found, the section at them, the weighted error left, and how the search ended."""

    pressures_kpa: FloatArray  #: (k,) kPa
    section: SectionResult
    error_mm: FloatArray  #: (3,) the weighted error e at the end, mm
    iterations: int  #: forward solves made
    converged: bool  #: |e| fell below the tolerance
    stopped_because: str


def arc_vector(kappa: float, phi: float, length: float) -> FloatArray:
    """``(theta cos phi, theta sin phi, L)`` (3,): rad, rad, mm."""
    theta = kappa * length
    return np.array([theta * np.cos(phi), theta * np.sin(phi), length])


def weighted_error(vector: FloatArray, target: FloatArray) -> FloatArray:
    """The weighted error (3,) mm of an arc vector against the target's (see the module's docstring)."""
    half = 0.5 * target[2]
    return np.array([half * (vector[0] - target[0]), half * (vector[1] - target[1]), vector[2] - target[2]])


def _arc_jacobian(centerline: FloatArray, fractions: FloatArray, d_centerline: FloatArray) -> FloatArray:
    """``d(arc vector)/dp`` (3, k) by central differences of the fit along ``d_centerline`` (k, n, 3) mm/kPa."""
    length = float(np.linalg.norm(np.diff(centerline, axis=0), axis=1).sum())
    columns = []
    for d in d_centerline:
        h = ARC_STEP_SHARE * length / max(float(np.abs(d).max()), 1e-300)
        plus = arc_vector(*arc_of(centerline + h * d, fractions)[:3])
        minus = arc_vector(*arc_of(centerline - h * d, fractions)[:3])
        columns.append((plus - minus) / (2 * h))
    return np.stack(columns, axis=1)


class _Reached(Exception):  # noqa: N818 - a signal, not an error: the search may stop
    """Raised inside the search when an evaluation's error is below the tolerance."""


class _TimeUp(Exception):  # noqa: N818 - a signal, not an error: the search must stop
    """Raised inside the search when a trial ends past the time limit."""


#: Told of each trial: (its number from 1, pressures (k,) kPa, its error's norm mm (inf: no equilibrium), seconds).
TrialListener = Callable[[int, FloatArray, float, float], None]


class _Evaluations:
    """Forward solves by pressures, each continued from the last equilibrium, kept for the Jacobian at that point."""

    def __init__(self, section: SectionMesh, law: HyperelasticLaw, target: FloatArray, newton: NewtonSettings,
                 settings: InverseSettings, on_trial: TrialListener | None, thread: HoopThread | None):
        self.prepared = prepare_section(section, law, thread)
        self.target, self.newton, self.tolerance_mm = target, newton, settings.tolerance_mm
        self.time_limit_s, self.on_trial, self.started = settings.time_limit_s, on_trial, time.perf_counter()
        self.trials = 0
        self.states: dict[bytes, tuple[FloatArray, SectionResult]] = {}
        self.last: tuple[FloatArray, FloatArray] | None = None
        self.rates: dict[bytes, FloatArray] = {}  # du/dp (k, V, 3) where the Jacobian was taken
        self.solves = 0
        self.failed: list[str] = []

    def state(self, p: FloatArray) -> tuple[FloatArray, SectionResult]:
        key = np.asarray(p, float).tobytes()
        if key not in self.states:
            rate = None if self.last is None else self.rates.get(self.last[1].tobytes())
            u, record = solve_pressures(self.prepared.problem, p, self.newton, start=self.last,
                                        solver=self.prepared.solver, start_rate=rate)
            self.solves += 1
            self.last = (u, np.array(p, float))
            self.states[key] = (u, measure_section(self.prepared, u, p, record))
        return self.states[key]

    def error(self, p: FloatArray) -> FloatArray:
        result = self.state(p)[1]
        return weighted_error(arc_vector(result.kappa, result.phi, result.length), self.target)

    def error_or_stop(self, p: FloatArray) -> FloatArray:
        try:
            error = self.error(p)
        except SolveError as err:
            if self.last is None:
                raise
            # a trial beyond what the solve reaches: a large error makes the trust region shrink
            self.failed.append(str(err))
            error = np.full(len(self.target), FAILED_TRIAL_MM)
        self._told(p, float(np.linalg.norm(error)) if error[0] != FAILED_TRIAL_MM else float("inf"))
        if np.linalg.norm(error) <= self.tolerance_mm:
            raise _Reached(np.array(p, float))
        if self.time_limit_s is not None and time.perf_counter() - self.started > self.time_limit_s:
            raise _TimeUp()
        return error

    def _told(self, p: FloatArray, norm: float) -> None:
        self.trials += 1
        if self.on_trial is not None:
            self.on_trial(self.trials, np.array(p, float), norm, time.perf_counter() - self.started)

    def best(self) -> FloatArray:
        """The pressures of the converged trial with the smallest error."""
        key = min(self.states, key=lambda k: float(np.linalg.norm(self.error(np.frombuffer(k)))))
        return np.frombuffer(key).copy()

    def jacobian(self, p: FloatArray) -> FloatArray:
        u, result = self.state(p)
        prepared = self.prepared
        du = pressure_sensitivity(prepared.problem, u, p, prepared.solver)
        self.rates[np.asarray(p, float).tobytes()] = du
        d_centerline = np.stack([prepared.centerline_motion(d) for d in du])
        jacobian = _arc_jacobian(result.centerline, prepared.fractions, d_centerline)
        return np.diag([0.5 * self.target[2], 0.5 * self.target[2], 1.0]) @ jacobian


def _reach(runs: _Evaluations, kappa: float, converged: bool) -> str:
    """When the search fell short: the largest curvature any converged solve reached, at which pressures, and how
    many trials found no equilibrium (past a chamber's ballooning limit there is none to solve)."""
    if converged or not runs.states:
        return ""
    reached = max(runs.states.values(), key=lambda state: state[1].kappa)[1]
    text = (f"; the largest bend reached: curvature {reached.kappa:.4g} 1/mm (the target's {kappa:.4g}) at "
            f"{', '.join(f'{p:.1f}' for p in reached.pressures_kpa)} kPa")
    return text + (f"; {len(runs.failed)} trials found no equilibrium" if runs.failed else "")


def find_pressures(section: SectionMesh, law: HyperelasticLaw, target: tuple[float, float, float],
                   settings: InverseSettings, newton: NewtonSettings, on_trial: TrialListener | None = None,
                   thread: HoopThread | None = None) -> InverseResult:
    """The pressures (k,) kPa whose section best matches the arc ``target`` = (kappa 1/mm, phi rad, L mm).

    ``on_trial`` is told of every trial (see the module's docstring); ``thread``: the chambers' hoop winding.

    Raises
    ------
    SolveError
        A forward solve did not converge.
    """
    from scipy.optimize import least_squares

    runs = _Evaluations(section, law, arc_vector(*target), newton, settings, on_trial, thread)
    start = np.full(section.chamber_count, settings.start_kpa)
    try:
        found = least_squares(runs.error_or_stop, start, jac=runs.jacobian, bounds=(0.0, settings.max_pressure_kpa),
                              method="trf", x_scale=settings.max_step_kpa, xtol=1e-10, ftol=1e-12, gtol=1e-12,
                              max_nfev=settings.max_iterations)
        p, message = np.asarray(found.x, float), str(found.message)
    except _Reached as reached:
        p, message = reached.args[0], "the error is below the tolerance"
    except _TimeUp:
        p = runs.best()
        message = (f"the time limit of {settings.time_limit_s:g} s was reached after {runs.trials} trials "
                   f"({time.perf_counter() - runs.started:.0f} s); the best trial is kept")
    result = runs.state(p)[1]
    error = runs.error(p)
    converged = bool(np.linalg.norm(error) <= settings.tolerance_mm)
    conditioning = np.linalg.svd(runs.jacobian(p), compute_uv=False)
    failed = f"; {len(runs.failed)} trial solves did not converge (a step back each)" if runs.failed else ""
    why = (f"{message} ({runs.solves} forward solves{failed}; the weighted Jacobian's singular values "
           f"{', '.join(f'{v:.3g}' for v in conditioning)} mm/kPa){_reach(runs, target[0], converged)}")
    return InverseResult(p, result, error, runs.solves, converged, why)
