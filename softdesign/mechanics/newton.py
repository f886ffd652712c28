"""Static equilibrium by Newton's method with load stepping: the pressures grow from 0 in steps, each solved.

At a load factor ``t`` the residual is ``R(u) = f_int(u) - t f_p(u)`` with the
follower pressure forces ``f_p`` of :mod:`softdesign.mechanics.pressure`, and
the Newton matrix is its consistent derivative ``K(u) - t dF_p/dx`` restricted
to the free unknowns, factored (SuperLU) in a nested-dissection order found
once per problem (:mod:`softdesign.mechanics.linear_solve`).  A section is
solved in quadratic tetrahedra with a mean dilatation per element
(:mod:`softdesign.mechanics.quadratic`): that matrix is as sparse as the mesh.

Newton's method there is the mixed (u, p) one with the element pressure
condensed out.  Near incompressibility (kappa / mu ~ 10^3) an update that is
right to first order still misses each element's volume at second order, and
``U'(theta)`` of the new volume is then a pressure tens of times too large; the
plain method puts that pressure into the next matrix's geometric part, and
needs 5-7 iterations a step.  The mixed method keeps each element's pressure as
an unknown, updated by its linearization
(:func:`~softdesign.mechanics.quadratic.linearized_pressure`), and the matrix
takes that one; the residual is the same, so is the equilibrium it converges
to.  The reinforcement's fibres carry their strain the same way (their tension in
the matrix is the linearized one: :mod:`softdesign.mechanics.reinforcement`).
Measured on the sample case's base section at 20 kPa in one chamber
(17,757 unknowns): 35 factorizations and 103 s before, 9 and 34 s after, the
curvature equal to 1e-16.  For linear
tetrahedra (average nodal pressure), the volumetric part couples each node
with its neighbours' neighbours; the step is solved instead from the
equivalent augmented system with one volume unknown ``q`` per node
(:class:`~softdesign.mechanics.assembly.Tangent`)::

    [K - t dF_p/dx   G^T        ] [du]   [-R]
    [G              -diag(c)    ] [dq] = [ 0],   c_a = V_a / U''(J_a),

whose elimination of ``dq = diag(1/c) G du`` gives back the exact tangent,
and whose sparse LU fills in about half as much (measured with SuperLU's
COLAMD order: on 7k unknowns 8 M entries and 2.5 s against 17 M and 20 s).  A step converges when the free
residual is below ``rtol`` times the free pressure load of that step (plus
``atol``).  A step that does not converge in ``max_iterations``, or whose trial
turns an element inside out, is halved, down to the smallest step, ``1 /
(load_steps 2^max_cutbacks)`` of the load; when a step that small fails the
solve stops with a :class:`~softdesign.errors.SolveError` naming the step, the
load factor and the residual: never a silent answer.  The bound is on the
step's length, not on the halvings over the solve: a long path has its
hiccups (a doubled step that overshoots, a thread's buckling kink), and a
budget over the whole solve spent them and stopped far from any limit (the
sample single-supply device with patched ends stopped at 0.69 of its P* after
20 halvings spread over 29 steps, none more than two in a row; the 12 mm
test section with patched ends at 325 kPa, against 703 kPa with the bound on
the length).  Nor is it a count of halvings in a row, which lets a path creep
towards a limit point in ever smaller steps that each converge (the same
section took 40 steps of 1e-5 to 2e-4 of the load near 703 kPa).  A step
that converged in ``EASY_STEP_ITERATIONS`` or fewer doubles the next, unless
it was itself halved (the length that failed is not tried again at once).

A length that failed is not tried again soon
    Doubling after every easy step ping-pongs at a length the path cannot
    take: on the curved sample device from 143 kPa on, steps of 7.0 kPa
    converged in four iterations each, the doubled 14.0 kPa failed (stalling
    or an element turned inside out after 2-5 iterations), the halving
    converged, and so on: a failure every second step, 25 halvings and 79
    Newton solves (359 residual evaluations) to P*.  So for
    ``FAILED_LENGTH_MEMORY`` converged steps after a failure, an easy step
    grows the next at most to ``FAILED_LENGTH_SHARE`` of the length that
    failed.  Measured on that device (curved walls, P* 446.57 kPa, one
    process with another beside it): 7 halvings, 54 Newton solves, 284
    residual evaluations, 279 s of CPU against 385 s; growing by 1.5 only
    after two easy steps in a row (as some commercial codes do) took 316 s.
    Steps shorter than a failed one converge to the same equilibrium (the
    path only starts each step); a solve near a limit point still stops at a
    step of the smallest length, not before.

When the mixed fibres cycle
    The fibres' mixed strain helps where a thread stretches; where it turns
    instead (a patched chamber cap, its two crossed families nearly
    inextensible, tilting under the pressure) the linearized strain misses
    the turn's ``|w|^2 / 2``, and the iteration can cycle without converging:
    the VMTK aorta's single-supply device with curved walls
    (:mod:`~softdesign.mechanics.curved_walls`) and its backbone stopped at
    79.9 kPa of its 267.2 kPa, every halving down to 1/512 of the load
    cycling between 20 and 400 mN on its second section's distal cap.  The
    linear solves were exact (1e-12) and the tangent consistent; the plain
    method from the same start converged there in about ten iterations.  So a step
    the mixed method fails is tried once more, from the same start, by the
    plain method (the fibres' tension in the matrix their own), before it is
    halved: that device then reached its P* (32 steps, 175 iterations, one
    step plain, 12 halvings, 233 s of CPU).  A step the mixed method
    converges is unchanged; the straight sample device at its P* moved by
    3e-6 mm (tip 9.311664 against 9.311667 mm from the designed chain).  Only
    a step that went through every iteration is tried again: one stopped
    early by an element turned inside out is halved at once, as before (on
    the curved sample device 23 mixed steps failed, most within 4-5
    iterations, and when each was retried 15 plain attempts failed too: 428 s
    of CPU to P*, 378 s retrying only the full-length failures).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import SolveError
from softdesign.mechanics.assembly import (
    InvertedElementError,
    Tangent,
    force_and_tangent,
    internal_force,
    volumetric_state,
)
from softdesign.mechanics.linear_solve import TangentSolver
from softdesign.mechanics.pressure import pressure_load
from softdesign.mechanics.quadratic import (
    QuadraticMesh,
    QuadraticState,
    linearized_pressure,
    quadratic_force,
    quadratic_force_and_tangent,
    quadratic_state,
)
from softdesign.mechanics.quadratic_pressure import quadratic_pressure_load
from softdesign.mechanics.reinforcement import FibreMembrane
from softdesign.mechanics.tets import TetMesh
from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class NewtonSettings:
    """How the load is stepped and when Newton stops.

    Attributes
    ----------
    load_steps : equal load increments to start with (>= 1)
    max_iterations : Newton iterations per step (>= 1)
    max_cutbacks : the smallest load step is ``1 / (load_steps 2^max_cutbacks)`` of the load (>= 0)
    rtol : residual tolerance relative to the step's pressure load
    atol : absolute residual tolerance, mN
    path_rtol : the tolerance of the steps before the last (None: ``rtol``).  A hyperelastic solid's equilibrium
        does not depend on the path to it, so an intermediate step only has to start the next one well: the last
        step still converges to ``rtol``.  Measured on the sample single-supply device at P*: 1e-4 took 307
        factorizations against 336, and its figures moved by 3e-7 mm (tip 9.311667 against 9.311670 mm).
    """

    load_steps: int = 4
    max_iterations: int = 12
    max_cutbacks: int = 6
    rtol: float = 1e-8
    atol: float = 1e-10
    path_rtol: float | None = None


@dataclass(frozen=True)
class PressureProblem:
    """A mesh, its law, the fixed unknowns and pressurised walls.

    Attributes
    ----------
    mesh : the reference mesh: linear tetrahedra (average nodal pressure) or quadratic ones (mean dilatation)
    law : the material
    fixed : (3V,) bool, unknowns held at zero displacement
    faces : (F, 3) int, wall triangles (F, 6 for a quadratic mesh), normals out of the cavity
    face_cavity : (F,) int, which cavity (index into the pressures) each face bounds
    fibres : the reinforcement's fibres on 6-node faces (:mod:`softdesign.mechanics.reinforcement`), or None
    lids : (L, 3) int, flat 3-node triangles that also carry a cavity's pressure (a cavity's flat end), or None
    lid_cavity : (L,) int, the cavity of each lid triangle
    springs : (3V, 3V) constant symmetric matrix, mN/mm: linear springs of energy ``u^T S u / 2`` (ties), or None
    """

    mesh: TetMesh | QuadraticMesh
    law: HyperelasticLaw
    fixed: np.ndarray
    faces: IntArray
    face_cavity: IntArray
    fibres: FibreMembrane | None = None
    lids: IntArray | None = None
    lid_cavity: IntArray | None = None
    springs: sp.csr_matrix | None = None


@dataclass
class SolveRecord:
    """What the solve did: per converged step the load factor, iterations and residual history (mN)."""

    load_factors: list[float] = field(default_factory=list)
    iterations: list[int] = field(default_factory=list)
    residuals: list[list[float]] = field(default_factory=list)
    cutbacks: int = 0  #: step halvings over the whole solve
    plain_steps: int = 0  #: steps converged by the plain method after the mixed one failed (module docstring)


def check_admissible(problem: PressureProblem, u: FloatArray) -> None:
    """Raise InvertedElementError when the displacement ``u`` turns an element inside out."""
    if isinstance(problem.mesh, QuadraticMesh):
        quadratic_state(problem.mesh, problem.law, u)
    else:
        volumetric_state(problem.mesh, problem.law, u)


def pressure_forces(problem: PressureProblem, positions: FloatArray, cavity_pressures: FloatArray,
                    want_tangent: bool) -> tuple[FloatArray, sp.csr_matrix | None]:
    """The cavities' pressure forces (3V,) mN on the deformed walls (and lids), and ``dF/dx`` if asked."""
    load = quadratic_pressure_load if isinstance(problem.mesh, QuadraticMesh) else pressure_load
    f, dF = load(positions, problem.faces, cavity_pressures[problem.face_cavity], want_tangent)
    if problem.lids is not None and problem.lid_cavity is not None:
        f_lid, dF_lid = pressure_load(positions, problem.lids, cavity_pressures[problem.lid_cavity], want_tangent)
        f = f + f_lid
        dF = None if dF is None or dF_lid is None else dF + dF_lid
    return f, dF


def _residual(problem: PressureProblem, u: FloatArray, cavity_pressures: FloatArray, tangent: bool,
              element_pressure: FloatArray | None = None, fibre_strain: FloatArray | None = None
              ) -> tuple[FloatArray, FloatArray, Tangent | None, QuadraticState | None]:
    """Residual (3V,), the pressure load (3V,), if asked the Newton matrix, and the quadratic state, at ``u`` (V, 3).

    ``element_pressure`` (quadratic elements) and ``fibre_strain`` (the fibres' points) are the mixed method's
    unknowns the matrix carries (None: those of ``u``).
    """
    mesh, law, positions = problem.mesh, problem.law, problem.mesh.points + u
    f_extra, K_extra = np.zeros(mesh.dof_count), sp.csr_matrix((mesh.dof_count, mesh.dof_count))
    if problem.fibres is not None:
        f_fibre, K_fibre = problem.fibres.force_and_tangent_at(u, tangent, fibre_strain)
        f_extra, K_extra = f_extra + f_fibre, K_extra if K_fibre is None else K_extra + K_fibre
    if problem.springs is not None:
        f_extra, K_extra = f_extra + problem.springs @ u.ravel(), K_extra + problem.springs
    f_p, dfp = pressure_forces(problem, positions, cavity_pressures, tangent)
    if isinstance(mesh, QuadraticMesh):
        state_q = quadratic_state(mesh, law, u)
        if not tangent or dfp is None:
            return quadratic_force(mesh, law, state_q) + f_extra - f_p, f_p, None, state_q
        f_int, K_q = quadratic_force_and_tangent(mesh, law, state_q, element_pressure)
        K_q = K_q + K_extra - dfp
        return f_int + f_extra - f_p, f_p, Tangent(K_q, sp.csr_matrix((0, mesh.dof_count)), np.zeros(0)), state_q
    state = volumetric_state(mesh, law, u)
    if not tangent or dfp is None:
        return internal_force(mesh, law, state) + f_extra - f_p, f_p, None, None
    f_int, K = force_and_tangent(mesh, law, state)
    return f_int + f_extra - f_p, f_p, Tangent(K.K + K_extra - dfp, K.G, K.compliance), None


def tangent_solver(tangent: Tangent, free: np.ndarray, solver: TangentSolver) -> Callable[[FloatArray], FloatArray]:
    """The solver ``r (3V,) -> du (3V,)`` of the Newton matrix on the free unknowns (fixed ones get 0)."""
    n_free = int(free.sum())
    if tangent.G.shape[0]:  # linear tetrahedra: the augmented system with one volume unknown per node
        G = sp.csr_matrix(tangent.G[:, free])
        blocks = [[sp.csr_matrix(tangent.K[free][:, free]), sp.csr_matrix(G.T)],
                  [G, sp.csr_matrix(sp.diags(-tangent.compliance))]]
        factors = solver.factor(sp.csc_matrix(sp.bmat(blocks)))
        padding = np.zeros(factors.shape[0] - n_free)
    else:  # quadratic tetrahedra: the matrix on the free unknowns, gathered by the solver's kept plan
        whole = sp.csr_matrix(tangent.K)
        if not whole.has_canonical_format:
            whole.sum_duplicates()
        factors, padding = solver.factor_free(whole, free), np.zeros(0)

    def solve(r: FloatArray) -> FloatArray:
        du = np.zeros(len(free))
        du[free] = factors.matvec(np.concatenate([r[free], padding]))[:n_free]
        return du

    return solve


#: A load step that converged in this many residual evaluations (the converged one included) or fewer doubles the
#: next step's length.  The mixed method's steps take 5-6 on a section at any load (one overshoot, then quadratic
#: convergence to 1e-8); at 5, a continuation from 10 to 52 kPa on the sample case never lengthened its steps.
EASY_STEP_ITERATIONS = 6
#: For this many converged steps after a failed one, an easy step lengthens the next to at most
#: FAILED_LENGTH_SHARE of the length that failed (the module's docstring: "A length that failed ...").
FAILED_LENGTH_MEMORY = 8
FAILED_LENGTH_SHARE = 0.75
#: Halvings of a Newton update that turns an element inside out before the update is taken as it is.
UPDATE_HALVINGS = 4


def _admissible(problem: PressureProblem, u: FloatArray, du: FloatArray) -> FloatArray:
    """``u + s du`` with the largest ``s`` of 1, 1/2, ... 1/16 that inverts no element (else the full update)."""
    for k in range(UPDATE_HALVINGS + 1):
        trial = u + du / 2**k
        try:
            check_admissible(problem, trial)
        except InvertedElementError:
            continue
        return trial
    return u + du


def _newton_step(problem: PressureProblem, u: FloatArray, cavity_pressures: FloatArray, settings: NewtonSettings,
                 solver: TangentSolver, fibre_strain: FloatArray | None = None, rtol: float | None = None,
                 mixed_fibres: bool = True) -> tuple[FloatArray, list[float]] | tuple[None, list[float]]:
    """Equilibrium at ``cavity_pressures`` (k,) kPa from ``u``: the new displacement and residual history, or None
    if it failed.  ``fibre_strain``: the fibres' mixed strain at ``u`` (None: their strain under ``u``); ``rtol``:
    the residual tolerance relative to the pressure load (None: the settings'); ``mixed_fibres``: False takes the
    fibres' tension in the matrix from each iterate's own strain (the plain method; ``fibre_strain`` ignored)."""
    rtol = settings.rtol if rtol is None else rtol
    free = ~problem.fixed
    history: list[float] = []
    u = u.copy()
    pressure: FloatArray | None = None  # the mixed method's element pressures (None: U'(theta) of u)
    fibre_strain = fibre_strain if mixed_fibres else None
    for _ in range(settings.max_iterations):
        try:
            R, f_p, K, state = _residual(problem, u, cavity_pressures, True, pressure, fibre_strain)
        except InvertedElementError:
            return None, history
        norm = float(np.linalg.norm(R[free]))
        history.append(norm)
        if norm <= rtol * float(np.linalg.norm(f_p[free])) + settings.atol:
            return u, history
        if K is None:
            return None, history
        du = tangent_solver(K, free, solver)(-R)
        if not np.all(np.isfinite(du)):
            return None, history
        new_u = _admissible(problem, u, du.reshape(-1, 3))
        if state is not None:
            assert isinstance(problem.mesh, QuadraticMesh)
            pressure = linearized_pressure(problem.mesh, problem.law, state, new_u - u)
        if problem.fibres is not None and mixed_fibres:
            fibre_strain = problem.fibres.linearized_strains(u, new_u - u)
        u = new_u
    return None, history


def _predicted(problem: PressureProblem, u: FloatArray, t: float, target: float,
               previous: tuple[float, FloatArray] | None, first_rate: FloatArray | None) -> FloatArray:
    """The start of a load step, if it inverts no element: the last two equilibria extrapolated to ``target``
    (secant) or, before there are two, ``u + target * first_rate`` (the tangent at the start, when known)."""
    if previous is not None and t > previous[0]:
        guess = u + (target - t) / (t - previous[0]) * (u - previous[1])
    elif first_rate is not None and t == 0.0:
        guess = u + target * first_rate
    else:
        return u
    try:
        check_admissible(problem, guess)
    except InvertedElementError:
        return u
    return guess


class SolveStopped(SolveError):
    """A load step failed after every halving: the message, and the last equilibrium reached (kept for a caller
    that reports the largest load a device holds: its figures there)."""

    def __init__(self, message: str, displacement: FloatArray, load_factor: float, record: SolveRecord) -> None:
        super().__init__(message)
        self.displacement = displacement  #: (V, 3) mm, the last converged step's
        self.load_factor = load_factor  #: that step's share of the way from the start's pressures (0: none converged)
        self.record = record  #: the converged steps


def solve_pressures(problem: PressureProblem, pressures: FloatArray, settings: NewtonSettings,
                    start: tuple[FloatArray, FloatArray] | None = None, solver: TangentSolver | None = None,
                    start_rate: FloatArray | None = None,
                    on_step: Callable[[float, list[float]], None] | None = None) -> tuple[FloatArray, SolveRecord]:
    """Displacement (V, 3) mm at cavity ``pressures`` (k,) kPa, reached in load steps, and the record.

    The load path runs from zero, or from ``start`` = (displacement (V, 3) mm, pressures (k,) kPa), an
    equilibrium converged before (a hyperelastic solid's equilibrium does not depend on the path to it).
    ``solver`` keeps the order of its matrices from earlier solves of the same problem (a fresh one when
    None).  ``start_rate`` (k, V, 3) mm/kPa, ``du/dp`` at ``start``
    (:func:`pressure_sensitivity`), makes the first step start on the tangent rather than at ``start``.
    ``on_step`` is told of every converged step: its load factor and Newton residuals (a progress display).

    Raises
    ------
    SolveStopped
        A step did not converge after every allowed halving (its index, load factor and last residual; the last
        equilibrium reached).
    """
    pressures = np.asarray(pressures, float)
    u, p0 = (np.zeros_like(problem.mesh.points), np.zeros_like(pressures)) if start is None else start
    record = SolveRecord()
    t, dt, step = 0.0, 1.0 / settings.load_steps, 0
    previous: tuple[float, FloatArray] | None = None
    solver = TangentSolver() if solver is None else solver
    first_rate = None if start_rate is None else np.einsum("c,cvi->vi", pressures - p0, start_rate)
    smallest = dt / 2**settings.max_cutbacks
    halved = False  # the step being tried is a halving of one that failed
    failed: tuple[float, int] | None = None  # the last length that failed, and the steps converged since
    while t < 1.0 - 1e-12:
        target = min(1.0, t + dt)
        cavity_pressures = (1.0 - target) * p0 + target * pressures
        guess = _predicted(problem, u, t, target, previous, first_rate)
        # the fibres' mixed strain at the guess: the last equilibrium's, carried to the guess to first order
        strain = None if problem.fibres is None else problem.fibres.linearized_strains(u, guess - u)
        rtol = settings.rtol if target >= 1.0 or settings.path_rtol is None else settings.path_rtol
        new_u, history = _newton_step(problem, guess, cavity_pressures, settings, solver, strain, rtol)
        if new_u is None and problem.fibres is not None and len(history) == settings.max_iterations:
            # the mixed fibre strain cycled through every iteration (not an element turned inside out): the plain one
            new_u, plain = _newton_step(problem, guess, cavity_pressures, settings, solver, None, rtol, False)
            history = history + plain
            record.plain_steps += new_u is not None
        if new_u is None:
            if (target - t) / 2.0 < smallest * (1.0 - 1e-9):
                last = f"{history[-1]:.3g} mN" if history else "none (an element turned inside out)"
                raise SolveStopped(
                    f"the solve did not converge at load step {step + 1} (load factor {target:.4g} towards the "
                    f"pressures {', '.join(f'{p:g}' for p in pressures)} kPa) in a step of {target - t:.3g} of the "
                    f"load, the smallest allowed ({record.cutbacks} step halvings in all); "
                    f"last residual {last}; lower the pressures (a chamber that balloons past its largest "
                    "pressure has no equilibrium beyond it) or take more load steps", u, t, record)
            record.cutbacks += 1
            halved = True
            failed = (target - t, 0)
            dt = (target - t) / 2.0  # half the step tried (dt may have run past the end)
            continue
        previous = (t, u)
        u, t, step = new_u, target, step + 1
        record.load_factors.append(t)
        record.iterations.append(len(history))
        record.residuals.append(history)
        if on_step is not None:
            on_step(t, history)
        if failed is not None:
            failed = (failed[0], failed[1] + 1) if failed[1] < FAILED_LENGTH_MEMORY else None
        if len(history) <= EASY_STEP_ITERATIONS and not halved:
            # an easy step at a length that did not fail: the next may be twice as long, short of one that failed
            dt = 2.0 * dt if failed is None else min(2.0 * dt, FAILED_LENGTH_SHARE * failed[0])
        halved = False
    return u, record


def pressure_sensitivity(problem: PressureProblem, u: FloatArray, pressures: FloatArray,
                         solver: TangentSolver | None = None) -> FloatArray:
    """``du/dp_c`` (k, V, 3) mm/kPa at the equilibrium ``u`` (V, 3) of ``pressures`` (k,) kPa.

    Differentiating ``f_int(u) = f_p(u, p)`` gives ``(K - dF_p/dx) du/dp_c = f_c``, the
    forces of a unit pressure in cavity c alone on the deformed walls: solves with the Newton matrix there.
    """
    pressures = np.asarray(pressures, float)
    _, _, tangent, _ = _residual(problem, u, pressures, tangent=True)
    if tangent is None:
        raise SolveError("no tangent at the equilibrium for the pressure sensitivity")
    solve = tangent_solver(tangent, ~problem.fixed, TangentSolver() if solver is None else solver)
    positions = problem.mesh.points + u
    out = []
    for c in range(len(pressures)):
        unit, _ = pressure_forces(problem, positions, (np.arange(len(pressures)) == c).astype(float), False)
        out.append(solve(unit).reshape(-1, 3))
    return np.stack(out)
