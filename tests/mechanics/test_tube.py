"""Known answer: a thick-walled neo-Hookean tube inflated in plane strain (tests/helpers/tube_analytic.py).

Solved in the sections' formulation: quadratic tetrahedra with a mean dilatation per element
(:mod:`softdesign.mechanics.quadratic`), near-incompressible (kappa / mu = 1000).
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import SolveError
from softdesign.mechanics.continuation import ContinuationSettings, follow_pressures
from softdesign.mechanics.newton import (
    NewtonSettings,
    PressureProblem,
    pressure_forces,
    pressure_sensitivity,
    solve_pressures,
)
from softdesign.mechanics.quadratic import quadratic_faces, quadratic_fixed, quadratic_mesh
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from tests.helpers.fe_meshes import quarter_tube
from tests.helpers.tube_analytic import inflation_pressure, lame_displacement

INNER, OUTER, HEIGHT = 5.0, 10.0, 1.0
MU = 40.0
#: near-incompressible: kappa / mu = 1000 (Poisson's ratio 0.4995)
LAW = HyperelasticLaw("neo-hookean", MU / 2, 0.0, 0.0, 1000 * MU, "test")
#: The default test mesh: 4 radial, 8 angular divisions of a quarter tube, one layer (quadratic elements).
DEFAULT_COUNTS = (4, 8, 1)
#: The issue's bound on the analytic inflation relation.
INFLATION_RTOL = 0.02


def _problem(counts: tuple[int, int, int]) -> tuple[np.ndarray, PressureProblem]:
    points, tets = quarter_tube(INNER, OUTER, HEIGHT, counts)
    linear = make_tet_mesh(points, tets)
    mesh = quadratic_mesh(linear)
    faces = boundary_faces(linear.tets)
    on_inner = np.all(np.isclose(np.hypot(points[faces][..., 0], points[faces][..., 1]), INNER), axis=1)
    wall = quadratic_faces(mesh, faces[on_inner][:, [0, 2, 1]])  # normals out of the cavity, into the material
    fixed = np.zeros(points.shape, bool)
    fixed[:, 2] = True  # plane strain
    fixed[np.isclose(points[:, 0], 0.0), 0] = True  # symmetry planes
    fixed[np.isclose(points[:, 1], 0.0), 1] = True
    return points, PressureProblem(mesh, LAW, quadratic_fixed(mesh, fixed).ravel(), wall, np.zeros(len(wall), np.int64))


def _inflate(counts: tuple[int, int, int], pressure: float) -> float:
    """The mean deformed inner radius, mm, of the quarter tube at ``pressure`` kPa."""
    points, problem = _problem(counts)
    u, record = solve_pressures(problem, np.array([pressure]), NewtonSettings(load_steps=4))
    assert all(h[-1] < 1e-6 for h in record.residuals)
    nodes = np.isclose(np.hypot(points[:, 0], points[:, 1]), INNER)
    x = points[nodes] + u[: len(points)][nodes]
    return float(np.hypot(x[:, 0], x[:, 1]).mean())


@pytest.mark.parametrize("pressure", [5.0, 20.0])
def test_tube_follows_the_analytic_inflation(pressure: float) -> None:
    # at 20 kPa the inner radius grows by 68 %: well into the nonlinear range
    a = _inflate(DEFAULT_COUNTS, pressure)
    assert abs(inflation_pressure(MU, INNER, OUTER, a) / pressure - 1) < INFLATION_RTOL


@pytest.mark.slow
def test_tube_inflation_converges_under_refinement() -> None:
    # measured relative errors at 20 kPa: 4.6 %, 0.77 %, 0.15 % on 1, 2, 4 radial divisions (rates 2.6 and 2.3)
    errors = [abs(inflation_pressure(MU, INNER, OUTER, _inflate((n, 2 * n, 1), 20.0)) / 20.0 - 1) for n in (1, 2, 4)]
    assert errors[0] > errors[1] > errors[2]
    assert errors[1] / errors[2] > 4.0  # at least second order


def test_tube_small_pressure_is_lame() -> None:
    pressure = 0.05  # 0.1 % hoop strain: the linear limit
    a = _inflate(DEFAULT_COUNTS, pressure)
    expected = lame_displacement(MU, LAW.bulk_kpa, INNER, OUTER, pressure, INNER)
    # measured 0.6 % below (the polygonal inner wall); the analytic and linear answers agree to 1e-3
    assert abs((a - INNER) / expected - 1) < INFLATION_RTOL


def test_a_solve_that_does_not_converge_says_where() -> None:
    _, problem = _problem((2, 4, 1))
    stop = r"load step 1 \(load factor 1 .* in a step of 1 of the load, the smallest allowed \(0 step halvings in all\)"
    with pytest.raises(SolveError, match=stop + r"; last residual \d"):
        solve_pressures(problem, np.array([20.0]), NewtonSettings(load_steps=1, max_iterations=2, max_cutbacks=0))


def test_a_continuation_started_on_the_tangent_reaches_the_same_equilibrium() -> None:
    """From the equilibrium at 10 kPa with du/dp as the first step's predictor: the same answer as without, and
    the predictor's miss second order in the pressure step (its residual is no guide: near incompressibility a
    first-order guess misses each element's volume at second order, times kappa)."""
    _, problem = _problem(DEFAULT_COUNTS)
    settings = NewtonSettings(load_steps=1)
    start = np.array([10.0])
    u10, _ = solve_pressures(problem, start, settings)
    rate = pressure_sensitivity(problem, u10, start)
    misses = []
    for step in (1.0, 0.5):
        plain, _ = solve_pressures(problem, start + step, settings, start=(u10, start))
        tangent, _ = solve_pressures(problem, start + step, settings, start=(u10, start), start_rate=rate)
        assert np.abs(tangent - plain).max() < 1e-6 * np.abs(plain).max()
        misses.append(np.abs(u10 + step * rate[0] - plain).max())
        assert misses[-1] < 0.05 * np.abs(u10 - plain).max()
    assert 3.0 < misses[0] / misses[1] < 5.0  # half the step, a quarter of the miss


def test_the_volume_continuation_reaches_the_load_steps_equilibrium() -> None:
    """Below any limit the path ends at t = 1 on the same equilibrium as load steps (the plane-strain tube has none:
    its pressure rises to mu/2 ln(B^2/A^2) without a maximum)."""
    _, problem = _problem(DEFAULT_COUNTS)
    stepped, _ = solve_pressures(problem, np.array([20.0]), NewtonSettings(load_steps=4))
    path = follow_pressures(problem, np.array([20.0]), ContinuationSettings())
    assert path.status == "reached" and path.load_factor == 1.0
    assert np.abs(path.end.u - stepped).max() < 1e-6 * np.abs(stepped).max()
    assert np.all(np.diff(path.path[:, 0]) > 0)  # rising all the way
    assert path.record().load_factors[-1] == 1.0


def test_a_path_that_cannot_step_says_the_largest_load_it_reached() -> None:
    _, problem = _problem(DEFAULT_COUNTS)
    settings = ContinuationSettings(max_cutbacks=2, newton=NewtonSettings(max_iterations=1))
    path = follow_pressures(problem, np.array([20.0]), settings)
    assert path.status == "stopped" and path.load_factor == 0.0
    assert "stopped at 0 kPa (load factor 0, the largest it reached towards 20 kPa)" in path.stopped_because(
        np.array([20.0]))


def test_a_looser_path_ends_on_the_same_equilibrium_with_its_last_step_converged_in_full() -> None:
    # NewtonSettings.path_rtol loosens only the steps before the last (a hyperelastic equilibrium does not depend on
    # the path): the end is the fully converged solve's, to the last step's tolerance
    _, problem = _problem(DEFAULT_COUNTS)
    full, full_record = solve_pressures(problem, np.array([20.0]), NewtonSettings(load_steps=4))
    loose, loose_record = solve_pressures(problem, np.array([20.0]), NewtonSettings(load_steps=4, path_rtol=1e-3))
    assert loose_record.load_factors[-1] == 1.0
    load, _ = pressure_forces(problem, problem.mesh.points + loose, np.array([20.0]), False)
    assert loose_record.residuals[-1][-1] <= 1e-8 * np.linalg.norm(load[~problem.fixed])  # the last step to rtol
    assert max(h[-1] for h in loose_record.residuals[:-1]) > max(h[-1] for h in full_record.residuals[:-1])
    assert sum(loose_record.iterations) < sum(full_record.iterations)
    assert np.abs(loose - full).max() < 1e-6 * np.abs(full).max()
