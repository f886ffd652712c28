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
    within [0, max_pressure_kpa], ``x_scale`` the step size ``max_step_kpa``.
    It starts from ``start_kpa`` in every chamber or, when that is None, from the
    linear answer: the rest shape's sensitivity (one factorization) gives the
    bounded linear least-squares pressures (scipy's ``lsq_linear``), scaled down
    to ``max_step_kpa`` when any is above it (the rest shape's tangent is trusted
    as far as the search's first step), so the first trial lies near the answer
    whenever the section is near linear there.  Its
    Jacobian ``de/dp`` is the equilibrium's exact sensitivity ``du/dp``
    (:func:`~softdesign.mechanics.newton.pressure_sensitivity`) carried through
    the arc fit by central differences along it.  Each trial is one forward
    solve, continued from the converged equilibrium nearest in pressure whose
    ``du/dp`` is known and started on that tangent (the predictor
    ``u + du/dp (p - p_near)``), in load steps of at most ``STEP_KPA`` (from
    rest, ``FIRST_STEP_KPA``) (a hyperelastic solid's equilibrium does not
    depend on the path: the answer is the forward solve's from rest, to
    Newton's tolerance); a step that fails is halved, at most
    ``TRIAL_CUTBACKS`` times.  A trial whose solve does not converge (beyond
    what the chambers hold, or too far from its neighbour) counts as a very
    large error, so the trust region shrinks back (the start's must converge).
    At most ``max_iterations`` evaluations.
Stop at the best within the bounds
    At every equilibrium whose Jacobian it takes (the rest shape's included),
    the search asks the Gauss-Newton model on the bounds how much lower the
    error can go (:mod:`softdesign.mechanics.bounded_optimum`): when no
    feasible change of the pressures lowers it by more than
    ``STATIONARY_SHARE`` of it (or the tolerance), the point meets the bounded
    problem's first-order (KKT) conditions and the search stops there, without
    further trials: the best the section does, not converged when its error is
    above the tolerance (a target out of reach), with the bounds that hold it
    and the error's bend and length parts.  The result keeps the remaining
    error, says whether it is below ``tolerance_mm``, and gives the Jacobian's
    singular values: an unreinforced chamber balloons rather than lengthens, so
    the common pressure moves L little and the pressures are least determined
    along (1, 1, 1).
Cost
    A factorization of the Newton matrix is most of it (about 1.1 s CPU on the
    per-chamber demo's section 1 at the default mesh, 3.3-5 s of wall time at a
    load of 8).  Measured there: a solve from rest to 20 kPa in one step takes 5
    factorizations; continued from it to (22, 2, 0) kPa on the tangent, 3 (4
    without the tangent: its start overstretches the thread, residual 2e4 mN,
    yet Newton then converges faster); the Jacobian at an equilibrium, 1.  Before
    (a start at a tenth of the bound, two load steps of 5-7 iterations a trial,
    six halvings for a trial without equilibrium): on the VMTK aorta's section 1
    at q = 1, three trials in 378 s wall (182 s CPU, load 8), one of them 266 s.
    Round 4, section 1, ``--target 1`` (out of reach at 100 kPa): the demo's
    search started at 10 kPa in every chamber took 4 trials and 84
    factorizations, 126 s of CPU in-process (the first trial, from rest, 38 of
    them), the command 132 s wall; from the linear answer within its first
    step, stopped at its best within the bounds (chamber 2 on the 100 kPa
    bound), 4 trials and 45 factorizations, the command 55.8 s wall (55.3 s
    CPU, load 2.5) and 65.9 s in a later run (load 1: the machine's own speed
    swings, its forward line 45.7 and 50.1 s alike), the same error (12.90
    mm).  The aorta's: 184 s of CPU in-process before, the command 109-123 s
    wall after (1.260 mm, chamber 1 on the bound).  Most of it is the path from rest to the bound: a first load
    step from rest takes 10-12 Newton iterations, every later one 5-6,
    whatever its length (rest to 25 kPa: 23 factorizations of the 45).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import SolveError
from softdesign.mechanics.bounded_optimum import Stationarity, stationarity, why_left
from softdesign.mechanics.newton import NewtonSettings, SolveRecord, pressure_sensitivity, solve_pressures
from softdesign.mechanics.reinforcement import HoopThread
from softdesign.mechanics.section import SectionMesh, SectionResult, arc_of, measure_section, prepare_section
from softdesign.types import FloatArray

#: The error (mm, each component) given to the search for a trial whose solve did not converge.
FAILED_TRIAL_MM = 1e6
#: Central-difference step of the arc fit along the sensitivity, as a share of the section's length, 1.
ARC_STEP_SHARE = 1e-4
#: Step halvings a trial's solve may take (the Newton settings' own bound when lower).  A trial past what the
#: chambers hold has no equilibrium, and each halving tries again with up to ``max_iterations`` factorizations:
#: with six, one such trial took 266 s on the aorta's section; the search's trust region shrinks back instead.
TRIAL_CUTBACKS = 2
#: The search stops, not converged, when an accepted step lowers the squared error by less than this share of it
#: (scipy's ``ftol``), or moves the pressures by less than ``STALL_XTOL`` of their size: a target the section cannot
#: reach (beyond what the chambers hold, or shorter than the section: pressure only lengthens it) leaves an error
#: that further trials barely lower.  Near a reachable target Gauss-Newton lowers it by far more per step.
STALL_FTOL = 1e-2
STALL_XTOL = 1e-6
#: Newton iterations a trial's load step may take (the Newton settings' own bound when lower): the converging steps
#: of the demo's and the aorta's searches took 5-7; a step that has not converged by then is far from it.  A solve
#: from rest takes the caller's bound: its first step took 10-12 on the demo's section at 3-6 kPa.
TRIAL_ITERATIONS = 8
#: The largest pressure change (kPa, any chamber) one load step of a trial starts with: a trial continued further
#: takes more steps (solve_pressures doubles a step that converged easily).  Measured on the demo's section 1 with
#: its kevlar thread: from an equilibrium, steps of 25 kPa converge in 5-6 iterations and one of 50 kPa did not; from
#: rest, a first step of 3.1 or 6.3 kPa in 10-12, one of 25 kPa not at all (its residual grew to 3e6 mN).
STEP_KPA = 25.0
FIRST_STEP_KPA = 6.25
#: Newton's relative residual at which a trial's load steps stop (the caller's own when looser): a quadratically
#: converging step reaches about 1e-5 of its load one iteration before the 1e-8 that a final answer needs, and that
#: last iteration is one factorization of the five or six a step takes (the demo's section 1: load steps at 12.5 and
#: 100 kPa ran ..., 2.6, 2.9e-5, 2.1e-8 and ..., 0.046, 3.2e-7 mN).  The trial the search ends on is then solved again
#: from there to the caller's tolerance (:meth:`_Evaluations.polish`: one or two iterations), so the answer is the
#: forward solve's as before; the trials' errors and Jacobians on the way differ from those by about 1e-5 of the
#: displacement, far below what steers the search (STATIONARY_SHARE).
INTERMEDIATE_RTOL = 1e-5
#: The search stops at the best the section does within the bounds (:mod:`softdesign.mechanics.bounded_optimum`)
#: when, at an equilibrium, the Gauss-Newton model predicts that no feasible change of the pressures lowers the error
#: by more than this share of it (or than the tolerance).
STATIONARY_SHARE = 1e-3
#: Halvings of the linear start towards rest when it has no equilibrium (past what the chambers hold).
START_HALVINGS = 3


@dataclass(frozen=True)
class InverseSettings:
    """Bounds and stopping rules of the pressure search (kPa, mm)."""

    max_pressure_kpa: float
    start_kpa: float | None  #: every chamber's pressure at the start; None: the linear answer (module docstring)
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
    #: the search stopped where no feasible change of the pressures lowers the error (first order; not converged
    #: when that error is above the tolerance: the target is beyond the section's reach within the bounds)
    best_within_bounds: bool = False


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


class _Stationary(Exception):  # noqa: N818 - a signal, not an error: the search may stop
    """Raised inside the search at an equilibrium where no feasible change of the pressures lowers the error."""

    def __init__(self, pressures: FloatArray, found: Stationarity) -> None:
        super().__init__()
        self.pressures, self.found = pressures, found


#: Told of each trial: (its number from 1, pressures (k,) kPa, its error's norm mm (inf: no equilibrium), seconds).
TrialListener = Callable[[int, FloatArray, float, float], None]


class _Evaluations:
    """Forward solves by pressures, each continued from the nearest equilibrium, kept for the Jacobian there."""

    def __init__(self, section: SectionMesh, law: HyperelasticLaw, target: FloatArray, newton: NewtonSettings,
                 settings: InverseSettings, on_trial: TrialListener | None, thread: HoopThread | None):
        self.prepared = prepare_section(section, law, thread)
        self.target, self.tolerance_mm, self.max_pressure = target, settings.tolerance_mm, settings.max_pressure_kpa
        # load steps of at most STEP_KPA from the neighbour's tangent, FIRST_STEP_KPA from rest (no neighbour); at
        # most TRIAL_CUTBACKS halvings (a start beyond what the chambers hold took 84 factorizations with six)
        self.newton = replace(newton, max_cutbacks=min(newton.max_cutbacks, TRIAL_CUTBACKS),
                              rtol=max(newton.rtol, INTERMEDIATE_RTOL))
        self.final_newton = replace(newton, load_steps=1, max_cutbacks=min(newton.max_cutbacks, TRIAL_CUTBACKS))
        self.loose: set[bytes] = set()  # trials solved to INTERMEDIATE_RTOL only
        self.trial_newton = replace(self.newton, max_iterations=min(newton.max_iterations, TRIAL_ITERATIONS))
        self.time_limit_s, self.on_trial, self.started = settings.time_limit_s, on_trial, time.perf_counter()
        self.trials = 0
        self.states: dict[bytes, tuple[FloatArray, SectionResult]] = {}
        self.rates: dict[bytes, FloatArray] = {}  # du/dp (k, V, 3) where the Jacobian was taken
        self.jacobians: dict[bytes, FloatArray] = {}
        self.solves = 0
        self.failed: list[str] = []

    def _nearest(self, p: FloatArray) -> tuple[tuple[FloatArray, FloatArray], FloatArray] | None:
        """The converged equilibrium (u, its pressures) nearest ``p`` among those whose du/dp is known, and du/dp."""
        if not self.rates:
            return None
        key = min(self.rates, key=lambda k: float(np.linalg.norm(np.frombuffer(k) - p)))
        return (self.states[key][0], np.frombuffer(key).copy()), self.rates[key]

    def state(self, p: FloatArray) -> tuple[FloatArray, SectionResult]:
        p = np.asarray(p, float)
        key = p.tobytes()
        if key not in self.states:
            near = self._nearest(p)
            start, rate = (None, None) if near is None else near
            u, record = solve_pressures(self.prepared.problem, p, self._settings_to(p, start), start=start,
                                        solver=self.prepared.solver, start_rate=rate)
            self.solves += 1
            self.states[key] = (u, measure_section(self.prepared, u, p, record))
            if self.newton.rtol > self.final_newton.rtol:
                self.loose.add(key)
        return self.states[key]

    def polish(self, p: FloatArray) -> None:
        """Solve the trial at ``p`` again from its equilibrium to the caller's tolerance, when it was solved to
        INTERMEDIATE_RTOL only (its record gains that step)."""
        p = np.asarray(p, float)
        key = p.tobytes()
        if key not in self.loose:
            return
        loose, before = self.states[key]
        u, record = solve_pressures(self.prepared.problem, p, self.final_newton, start=(loose, p),
                                    solver=self.prepared.solver)
        record = SolveRecord(before.record.load_factors + record.load_factors,
                             before.record.iterations + record.iterations, before.record.residuals + record.residuals,
                             before.record.cutbacks + record.cutbacks)
        self.states[key] = (u, measure_section(self.prepared, u, p, record))
        self.loose.discard(key)

    def _settings_to(self, p: FloatArray, start: tuple[FloatArray, FloatArray] | None) -> NewtonSettings:
        """A trial's Newton settings: load steps of at most STEP_KPA from its start, FIRST_STEP_KPA from rest (with the
        caller's bound on iterations: a first step from rest takes more)."""
        if start is None or not np.any(start[1]):
            steps = math.ceil(float(np.max(p, initial=0.0)) / FIRST_STEP_KPA)
            return replace(self.newton, load_steps=max(self.newton.load_steps, steps))
        return replace(self.trial_newton, load_steps=max(1, math.ceil(float(np.max(np.abs(p - start[1]))) / STEP_KPA)))

    def error(self, p: FloatArray) -> FloatArray:
        result = self.state(p)[1]
        return weighted_error(arc_vector(result.kappa, result.phi, result.length), self.target)

    def error_or_stop(self, p: FloatArray) -> FloatArray:
        try:
            error = self.error(p)
        except SolveError as err:
            if not self.states:
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
        """``de/dp`` (3, k) mm/kPa at the equilibrium of ``p`` (kept: one factorization per point)."""
        key = np.asarray(p, float).tobytes()
        if key not in self.jacobians:
            u, result = self.state(p)
            prepared = self.prepared
            du = pressure_sensitivity(prepared.problem, u, p, prepared.solver)
            self.rates[key] = du
            d_centerline = np.stack([prepared.centerline_motion(d) for d in du])
            jacobian = _arc_jacobian(result.centerline, prepared.fractions, d_centerline)
            self.jacobians[key] = np.diag([0.5 * self.target[2], 0.5 * self.target[2], 1.0]) @ jacobian
        return self.jacobians[key]

    def jacobian_or_stop(self, p: FloatArray) -> FloatArray:
        """:meth:`jacobian`, and _Stationary when no feasible change of ``p`` lowers the error (above the tolerance)
        by more than STATIONARY_SHARE of it (:mod:`softdesign.mechanics.bounded_optimum`)."""
        jacobian, error = self.jacobian(p), self.error(p)
        found = stationarity(jacobian, error, p, self.max_pressure)
        if found.error_mm > self.tolerance_mm and found.is_optimum(STATIONARY_SHARE, self.tolerance_mm):
            raise _Stationary(np.array(p, float), found)
        return jacobian

    def linear_start(self, max_pressure_kpa: float) -> FloatArray:
        """The bounded linear least-squares pressures (k,) kPa from the rest shape: ``min |e0 + J0 p|`` on
        [0, max_pressure_kpa], with ``J0`` the sensitivity at rest (its du/dp then predicts the first trial)."""
        from scipy.optimize import lsq_linear

        rest = np.zeros(self.prepared.section.chamber_count)
        found = lsq_linear(self.jacobian_or_stop(rest), -self.error(rest), bounds=(0.0, max_pressure_kpa))
        return np.asarray(found.x, float)


def _converged_start(runs: _Evaluations, linear: FloatArray) -> FloatArray:
    """The linear answer, or its half, quarter, ... (at most ``START_HALVINGS`` times) when the section has no
    equilibrium there: the search starts from a converged trial (SolveError when none converges)."""
    for _ in range(START_HALVINGS):
        try:
            runs.state(linear)
            return linear
        except SolveError as err:
            runs.failed.append(str(err))
            linear = 0.5 * linear
    runs.state(linear)
    return linear


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
    bound, best = settings.max_pressure_kpa, False
    try:
        start = (_converged_start(runs, _inside(_within_step(runs.linear_start(bound), settings.max_step_kpa), bound))
                 if settings.start_kpa is None
                 else np.full(section.chamber_count, settings.start_kpa))
        found = least_squares(runs.error_or_stop, start, jac=runs.jacobian_or_stop, bounds=(0.0, bound),
                              method="trf", x_scale=settings.max_step_kpa, xtol=STALL_XTOL, ftol=STALL_FTOL, gtol=1e-12,
                              max_nfev=settings.max_iterations)
        p, message = np.asarray(found.x, float), str(found.message)
    except _Reached as reached:
        p, message = reached.args[0], "the error is below the tolerance"
    except _Stationary as stop:
        runs.polish(stop.pressures)  # the message's figures are the answer's
        p, best, message = stop.pressures, True, _best_within_bounds(runs, stop, target)
    except _TimeUp:
        p = runs.best()
        message = (f"the time limit of {settings.time_limit_s:g} s was reached after {runs.trials} trials "
                   f"({time.perf_counter() - runs.started:.0f} s); the best trial is kept")
    runs.polish(p)
    result = runs.state(p)[1]
    error = runs.error(p)
    converged = bool(np.linalg.norm(error) <= settings.tolerance_mm)
    conditioning = np.linalg.svd(runs.jacobian(p), compute_uv=False)
    failed = f"; {len(runs.failed)} trial solves did not converge (a step back each)" if runs.failed else ""
    why = (f"{message} ({runs.solves} forward solves{failed}; the weighted Jacobian's singular values "
           f"{', '.join(f'{v:.3g}' for v in conditioning)} mm/kPa){_reach(runs, target[0], converged)}")
    return InverseResult(p, result, error, runs.solves, converged, why, best)


def _within_step(pressures: FloatArray, step_kpa: float) -> FloatArray:
    """``pressures`` (k,) kPa scaled down, when any is above ``step_kpa``, to that largest (the direction kept)."""
    largest = float(np.max(pressures, initial=0.0))
    return pressures if largest <= step_kpa else pressures * (step_kpa / largest)


def _inside(pressures: FloatArray, bound: float) -> FloatArray:
    """``pressures`` (k,) kPa moved strictly inside [0, bound], as scipy's trust-region search moves its start (a
    relative 1e-10): its first trial is then the point the start solved, not a new one beside it."""
    return np.clip(pressures, 1e-10, bound * (1.0 - 1e-10))


def _best_within_bounds(runs: _Evaluations, stop: _Stationary, target: tuple[float, float, float]) -> str:
    """The message of a search that stopped where no feasible change lowers the error: the model's figures, why."""
    s, result = stop.found, runs.state(stop.pressures)[1]
    least = max(STATIONARY_SHARE * s.error_mm, runs.tolerance_mm)
    return (f"the best the section does within [0, {runs.max_pressure:g}] kPa, to first order: no change of the "
            f"pressures within the bounds lowers the error by more than {least:.3g} mm "
            f"(the linear model's least error {s.predicted_mm:.6g} mm against {s.error_mm:.6g} mm); "
            + why_left(s, runs.max_pressure, runs.error(stop.pressures), (result.kappa, result.phi, result.length),
                       target, runs.jacobian(stop.pressures)[2]))
