"""The thread embedded in the host elements (:mod:`softdesign.mechanics.embedded_thread`): its shape gradients are
the quadratic mesh's, its forces and tangent are the derivatives of its energy, and a straight bar with a stiff
fibre along its axis (through no node) stretches as the composite E A + E_t A_t away from its ends."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics import newton
from softdesign.mechanics.device import roundoff_floor_mn
from softdesign.mechanics.embedded_thread import (
    ThreadFibres,
    embedded_fibres,
    quadratic_gradients_at,
    thread_fibres,
)
from softdesign.mechanics.newton import NewtonSettings, PressureProblem, SolveRecord, solve_pressures
from softdesign.mechanics.quadratic import QUAD_POINTS, QuadraticMesh, quadratic_faces, quadratic_fixed, quadratic_mesh
from softdesign.mechanics.reinforcement import HoopThread, hoop_membrane
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from tests.helpers.fe_meshes import grid_tets, oriented

MU = 40.0
#: Ecoflex-like neo-Hookean, kappa / mu = 1000 (E = 3 mu to 0.1 %).
LAW = HyperelasticLaw("neo-hookean", MU / 2, 0.0, 0.0, 1000 * MU, "test")
#: A 4 x 4 mm bar 60 mm long, 3 x 3 x 30 hexahedra of six tets: its axis x = y = 2, where the fibre runs (on the
#: centroid: a pull does not bend it), crosses the middle column's elements and their faces at no node.  Long:
#: the pull on the tip face reaches the fibre through the silicone's shear over a few bar widths at each end.
SIDE_MM, LENGTH_MM, FIBRE_XY = 4.0, 60.0, (2.0, 2.0)
#: Where the strain is measured: the middle third, away from the ends' load transfer.
MIDDLE_MM = (20.0, 40.0)
#: Gradients at the rule's points: the same formula, rounding only.
GRAD_TOL = 1e-12
#: The plain method's equilibrium against the mixed one's: each converged to 1e-8 of the load (measured: 7e-15).
PLAIN_RTOL = 1e-8
#: Finite differences (central, step 1e-6 mm) against the analytic force and tangent, relative to their size.
FD_RTOL = 1e-5


@functools.cache
def _bar() -> QuadraticMesh:
    axes = [np.linspace(0, SIDE_MM, 4), np.linspace(0, SIDE_MM, 4), np.linspace(0, LENGTH_MM, 31)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return quadratic_mesh(make_tet_mesh(points, oriented(points, grid_tets((3, 3, 30)))))


def _fibre_line() -> np.ndarray:
    return np.array([[*FIBRE_XY, 0.0], [*FIBRE_XY, LENGTH_MM]])


def test_gradients_at_the_rule_points_are_the_meshs() -> None:
    mesh = _bar()
    elements = np.arange(len(mesh.cells))
    for q, bary in enumerate(QUAD_POINTS):
        grads = quadratic_gradients_at(mesh.linear.grads, np.repeat(bary[None], len(elements), axis=0))
        np.testing.assert_allclose(grads, mesh.grads[:, q], rtol=0, atol=GRAD_TOL)


def test_the_fibre_at_rest_is_its_unit_tangent_with_no_strain() -> None:
    fibres = embedded_fibres(_bar(), _fibre_line(), HoopThread(1.0, 0.2, 1e6), 3 * MU, 0.5)
    np.testing.assert_allclose(fibres.reference, np.broadcast_to([0.0, 0.0, 1.0], fibres.reference.shape),
                               rtol=0, atol=GRAD_TOL)
    np.testing.assert_allclose(fibres.weights.sum(), LENGTH_MM, rtol=1e-12)
    assert np.all(fibres.strains_at(np.zeros_like(_bar().points)) == 0.0)


def _mixed_fibres() -> ThreadFibres:
    """A hoop membrane on the bar's side y = 0 (six slots) and the embedded fibre (ten), as one set."""
    mesh = _bar()
    faces = boundary_faces(mesh.linear.tets)
    side = faces[np.all(np.isclose(mesh.points[faces][..., 1], 0.0), axis=1)]
    wall = quadratic_faces(mesh, side)
    thread = HoopThread(0.5, 0.2, 1e4)
    hoop = hoop_membrane(mesh.points, wall, np.tile([0.0, 0.0, 1.0], (len(wall), 1)), np.full(len(wall), 1.0),
                         thread, 3 * MU)
    spine = embedded_fibres(mesh, _fibre_line(), thread, 3 * MU, 1.0)
    both = thread_fibres([hoop, spine])
    assert both is not None
    return both


def test_force_and_tangent_are_the_energys_derivatives() -> None:
    fibres = _mixed_fibres()
    rng = np.random.default_rng(7)
    u = 0.02 * rng.standard_normal(_bar().points.shape)
    force, tangent = fibres.force_and_tangent_at(u, True)
    assert tangent is not None
    step, direction = 1e-6, rng.standard_normal(u.shape)
    plus, minus = u + step * direction, u - step * direction
    energy_slope = (fibres.energy_at(plus) - fibres.energy_at(minus)) / (2 * step)
    np.testing.assert_allclose(energy_slope, force @ direction.ravel(), rtol=FD_RTOL)
    force_slope = (fibres.force_and_tangent_at(plus, False)[0] - fibres.force_and_tangent_at(minus, False)[0]) / (
        2 * step)
    np.testing.assert_allclose(force_slope, tangent @ direction.ravel(), rtol=0,
                               atol=FD_RTOL * np.abs(tangent @ direction.ravel()).max())


def _middle_strain(fibre: HoopThread | None, pull_kpa: float) -> float:
    """:func:`_middle_solve`'s strain."""
    return _middle_solve(fibre, pull_kpa)[0]


def _middle_solve(fibre: HoopThread | None, pull_kpa: float) -> tuple[float, SolveRecord]:
    """The bar's axial strain over its middle third (mean z displacement of its cross-sections there) under a pull
    ``pull_kpa`` on its tip face, its base held in z only (and the least in x, y to hold it: free to narrow), with
    the embedded ``fibre`` or none."""
    mesh = _bar()
    faces = boundary_faces(mesh.linear.tets)
    tip = faces[np.all(np.isclose(mesh.points[faces][..., 2], LENGTH_MM), axis=1)]  # outward, +z: a pull
    corner = mesh.linear.points
    fixed = np.zeros((len(corner), 3), bool)
    base = np.isclose(corner[:, 2], 0.0)
    fixed[base, 2] = True
    fixed[base & np.isclose(corner[:, 0], 0.0) & np.isclose(corner[:, 1], 0.0), :2] = True
    fixed[base & np.isclose(corner[:, 0], SIDE_MM) & np.isclose(corner[:, 1], 0.0), 1] = True
    fibres = None if fibre is None else embedded_fibres(mesh, _fibre_line(), fibre, 3 * MU, 0.5)
    problem = PressureProblem(mesh, LAW, quadratic_fixed(mesh, fixed).ravel(), quadratic_faces(mesh, tip),
                              np.zeros(len(tip), np.int64), fibres)
    # the stiff fibre's rounding floor, as the device's solve takes it
    settings = NewtonSettings(load_steps=1, atol=max(NewtonSettings().atol, roundoff_floor_mn(problem)))
    u, record = solve_pressures(problem, np.array([pull_kpa]), settings)
    z = mesh.points[:, 2]
    low, high = (float(u[np.isclose(z, level), 2].mean()) for level in MIDDLE_MM)
    return (high - low) / (MIDDLE_MM[1] - MIDDLE_MM[0]), record


#: The bar's strain against F / (E A) and F / (E A + E_t A_t): the law's E is 3 mu to 1e-3 (kappa = 1000 mu), the
#: strain 1e-4 adds its square, and the ends' load transfer has decayed in the middle third (measured: 1.1e-5 off
#: with the fibre as stiff as the bar, 1.3e-3 with four times; over the whole bar, 4.7 % and 23 %).
COMPOSITE_RTOL = 2e-3


@pytest.mark.slow
@pytest.mark.parametrize("share", [1.0, 4.0])
def test_a_bar_with_an_embedded_fibre_stretches_as_the_composite(share: float) -> None:
    # Rule of mixtures: the bar's E A (3 mu, 16 mm^2) and the fibre's E_t A_t = share E A in parallel, at the
    # composite's strain 1e-4 (linear range).  About 2 s of CPU per solve.
    area = SIDE_MM**2
    bar = 3 * MU * area
    fibre = HoopThread(pitch_mm=1.0, diameter_mm=0.5, modulus_kpa=share * bar / (np.pi * 0.25**2))
    pull = 1e-4 * (bar + fibre.axial_stiffness_mn) / area  # kPa
    np.testing.assert_allclose(_middle_strain(None, pull), pull * area / bar, rtol=COMPOSITE_RTOL)
    np.testing.assert_allclose(_middle_strain(fibre, pull), 1e-4, rtol=COMPOSITE_RTOL)


def test_a_step_the_mixed_fibre_strain_fails_is_solved_again_by_the_plain_method(monkeypatch) -> None:
    # The mixed method's fibre strain can cycle where the threads turn rather than stretch (newton's docstring,
    # "When the mixed fibres cycle"); the step is then tried again from the same start by the plain method before
    # it is halved, when it went through every iteration.  Made to fail so here: the solve takes no halving, counts
    # one plain step, and reaches the mixed solve's equilibrium (the bar's strain) to the Newton tolerance.
    area = SIDE_MM**2
    bar = 3 * MU * area
    fibre = HoopThread(pitch_mm=1.0, diameter_mm=0.5, modulus_kpa=4.0 * bar / (np.pi * 0.25**2))
    pull = 1e-4 * (bar + fibre.axial_stiffness_mn) / area
    mixed, mixed_record = _middle_solve(fibre, pull)
    original, tries = newton._newton_step, []

    def mixed_fails(*args, **kwargs):  # cycling through every iteration (a history of max_iterations residuals)
        tries.append(kwargs.get("mixed_fibres", args[7] if len(args) > 7 else True))
        return (None, [1.0] * args[3].max_iterations) if tries[-1] else original(*args, **kwargs)

    monkeypatch.setattr(newton, "_newton_step", mixed_fails)
    plain, record = _middle_solve(fibre, pull)
    assert tries == [True, False]
    assert (mixed_record.plain_steps, record.plain_steps, record.cutbacks) == (0, 1, 0)
    np.testing.assert_allclose(plain, mixed, rtol=PLAIN_RTOL)

    # a mixed step stopped early (an element turned inside out: a short history) is halved, not tried again
    tries.clear()

    def mixed_stops_early(*args, **kwargs):
        tries.append(kwargs.get("mixed_fibres", args[7] if len(args) > 7 else True))
        if len(tries) == 1:
            return None, [1.0]
        return original(*args, **kwargs)

    monkeypatch.setattr(newton, "_newton_step", mixed_stops_early)
    halved, record = _middle_solve(fibre, pull)
    assert tries[:2] == [True, True] and record.plain_steps == 0 and record.cutbacks == 1
    np.testing.assert_allclose(halved, mixed, rtol=PLAIN_RTOL)
