"""The hoop thread's fibre membrane: its tangent is its forces' derivative, its forces its energy's gradient, and
its energy and direction are the thread's on a stretched tube wall (:mod:`softdesign.mechanics.reinforcement`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softdesign.mechanics.quadratic import QuadraticMesh, quadratic_faces, quadratic_mesh
from softdesign.mechanics.reinforcement import FIBRE_STABILISATION, FibreMembrane, HoopThread, hoop_membrane
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from softdesign.types import FloatArray
from tests.helpers.fe_meshes import quarter_tube
from tests.helpers.fibre_rules import fibre_rule
from tests.helpers.finite_differences import assert_columns_match_central_differences

INNER, OUTER, HEIGHT = 2.0, 3.0, 1.0
#: The silicone's Young's modulus, kPa (3 mu of an Ecoflex-like mu = 40 kPa): the thread buckles at e = 4.4e-3.
MATRIX_KPA = 120.0
#: A polyester-like thread: 0.2 mm, 2 GPa, one turn every 0.5 mm.
THREAD = HoopThread(pitch_mm=0.5, diameter_mm=0.2, modulus_kpa=2.0e6)
#: Central differences at 1e-6 mm of forces up to ~1e4 mN: truncation ~1e-12 relative, round-off ~1e-6 mN.
FD_ATOL = 1e-4
H = 1e-6
#: Energies and stretches computed two ways in floating point.
EXACT_RTOL = 1e-12
#: An eigenvalue below this share of the six-point stiffness's largest is a zero-energy mode (round-off ~1e-16).
ZERO_ENERGY = 1e-10


def _wall(thread: HoopThread = THREAD) -> tuple[QuadraticMesh, FibreMembrane]:
    points, tets = quarter_tube(INNER, OUTER, HEIGHT, (2, 4, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    faces = boundary_faces(mesh.linear.tets)
    radius = np.hypot(points[faces][..., 0], points[faces][..., 1])
    inner = quadratic_faces(mesh, faces[np.all(np.isclose(radius, INNER), axis=1)])
    axes = np.tile([0.0, 0.0, 1.0], (len(inner), 1))
    return mesh, hoop_membrane(mesh.points, inner, axes, np.full(len(inner), INNER), thread, MATRIX_KPA)


def test_the_tangent_matches_finite_differences_of_the_forces() -> None:
    mesh, fibres = _wall()
    # a random motion about a 2 % radial inflation: threads stretched, some shortened past their buckling
    x = mesh.points * np.array([0.02, 0.02, 0.0]) + 0.02 * np.random.default_rng(3).standard_normal(mesh.points.shape)
    e = fibres.strains_at(x)
    assert (e > 0).any() and (e < -fibres.buckling_strain[:, None]).any()
    _, K = fibres.force_and_tangent_at(x, want_tangent=True)
    assert K is not None
    dense = K.toarray()
    np.testing.assert_allclose(dense, dense.T, atol=1e-9)  # the Hessian of an energy
    assert_columns_match_central_differences(
        dense, lambda y: fibres.force_and_tangent_at(y, want_tangent=False)[0], x, H, FD_ATOL, every=5)


def test_the_forces_are_the_energys_gradient() -> None:
    mesh, fibres = _wall()
    x = mesh.points * np.array([0.1, 0.1, 0.02])  # a displacement, mm
    f, _ = fibres.force_and_tangent_at(x, want_tangent=False)
    direction = np.random.default_rng(5).standard_normal(x.shape)
    h = 1e-6
    slope = (fibres.energy_at(x + h * direction) - fibres.energy_at(x - h * direction)) / (2 * h)
    np.testing.assert_allclose(f @ direction.ravel(), slope, rtol=1e-6)  # central difference of an energy ~1e2


@pytest.mark.parametrize("stretch", [1.2, 0.999, 0.9])
def test_a_uniformly_scaled_wall_stores_the_threads_energy(stretch: float) -> None:
    """Scaling the wall radially by lambda strains a hoop thread by e = (lambda^2 - 1) / 2: W = k e^2 / 2 per area,
    and past the buckling strain e_b the force stays at k e_b (W linear in e)."""
    hoop = HoopThread(pitch_mm=1e-6, diameter_mm=0.2, modulus_kpa=2.0e6)  # a pitch that makes it pure hoop
    mesh, fibres = _wall(hoop)
    x = mesh.points * np.array([stretch - 1.0, stretch - 1.0, 0.0])  # the displacement, mm
    area, k = float(fibres.law_weights.sum()), hoop.stiffness_mn_per_mm
    e, e_b = (stretch**2 - 1) / 2, hoop.buckling_strain(MATRIX_KPA)
    expected = k * e**2 / 2 if e >= -e_b else k * e_b**2 / 2 - k * e_b * (e + e_b)
    np.testing.assert_allclose(fibres.energy_at(x), expected * area, rtol=1e-9)  # the pitch's cos(beta) ~ 1e-7 squared
    np.testing.assert_allclose(fibres.thread_tension_at(x), hoop.axial_stiffness_mn * max(e, -e_b), rtol=1e-9)


def test_the_winding_follows_the_helix_angle_from_the_axis() -> None:
    """Stretching the wall axially by s alone: a helix at beta from the axis has I4 = cos^2(beta) s^2 + sin^2(beta)."""
    mesh, fibres = _wall()
    beta = math.atan(2 * math.pi * INNER / THREAD.pitch_mm)
    assert math.isclose(THREAD.winding_angle_rad(INNER), beta, rel_tol=EXACT_RTOL)
    s = 1.3
    a, e = fibres.fibre_vectors(mesh.points * np.array([0.0, 0.0, s - 1.0]))
    i4 = np.einsum("fqi,fqi->fq", a, a)
    np.testing.assert_allclose(i4, math.cos(beta) ** 2 * s**2 + math.sin(beta) ** 2, rtol=1e-9)
    np.testing.assert_allclose(e, (i4 - 1.0) / 2, rtol=0, atol=1e-15)  # the strain from u is I4's, to round-off
    np.testing.assert_allclose(np.linalg.norm(fibres.reference, axis=2), 1.0, rtol=0, atol=1e-15)  # unit at rest


def test_a_thread_needs_positive_data() -> None:
    with pytest.raises(ValueError, match="pitch_mm, diameter_mm and modulus_kpa > 0"):
        HoopThread(pitch_mm=0.0, diameter_mm=0.2, modulus_kpa=1e6)


def test_a_tiny_strain_far_from_the_origin_is_computed_to_its_own_precision() -> None:
    """The strain comes from the displacement, not from positions tens of mm away from the origin: at rest the
    forces are exactly zero, and a radial inflation of 1e-9 gives its strain to 1e-6 of itself.  (From positions,
    the rest strain's round-off was 1e-13, forces of 1e-5 mN that a solve's tolerance at a small load step could
    not get under; see the module's docstring.)"""
    points, tets = quarter_tube(INNER, OUTER, HEIGHT, (2, 4, 2))
    far = points + np.array([0.0, 0.0, 30.0])  # a section's tip, 30 mm from its base frame's origin
    mesh = quadratic_mesh(make_tet_mesh(far, tets))
    faces = boundary_faces(mesh.linear.tets)
    radius = np.hypot(far[faces][..., 0], far[faces][..., 1])
    inner = quadratic_faces(mesh, faces[np.all(np.isclose(radius, INNER), axis=1)])
    hoop = HoopThread(pitch_mm=1e-6, diameter_mm=0.2, modulus_kpa=2.0e6)  # pure hoop
    fibres = hoop_membrane(mesh.points, inner, np.tile([0.0, 0.0, 1.0], (len(inner), 1)),
                           np.full(len(inner), INNER), hoop, MATRIX_KPA)
    f, _ = fibres.force_and_tangent_at(np.zeros_like(mesh.points), want_tangent=False)
    assert not np.any(f)
    stretch = 1e-9
    e = fibres.strains_at(mesh.points * np.array([stretch, stretch, 0.0]))
    np.testing.assert_allclose(e, stretch + stretch**2 / 2, rtol=1e-6, atol=0)  # the pitch's 1e-13 and round-off


def test_the_linearized_strain_is_the_strains_first_order() -> None:
    # e(u + s) - linearized(u, s) is the strain's second-order term |D s|^2 / 2: it falls as the step's square
    mesh, fibres = _wall()
    rng = np.random.default_rng(5)
    u = 0.02 * rng.standard_normal(mesh.points.shape)
    step = rng.standard_normal(mesh.points.shape)
    misses = [np.abs(fibres.strains_at(u + h * step) - fibres.linearized_strains(u, h * step)).max()
              for h in (1e-2, 1e-3)]
    assert misses[0] > 0.0
    assert 80.0 < misses[0] / misses[1] < 120.0  # 100 for a second-order remainder


def test_the_mixed_tangent_takes_the_carried_tension_and_the_same_forces() -> None:
    mesh, fibres = _wall()
    x = 0.02 * np.random.default_rng(7).standard_normal(mesh.points.shape)
    own = fibres.strains_at(x)
    f, K = fibres.force_and_tangent_at(x, want_tangent=True)
    f_same, K_same = fibres.force_and_tangent_at(x, want_tangent=True, strain=own)
    f_mixed, K_mixed = fibres.force_and_tangent_at(x, want_tangent=True, strain=own + 1e-3)
    assert K is not None and K_same is not None and K_mixed is not None
    np.testing.assert_array_equal(f_same, f)
    np.testing.assert_array_equal(f_mixed, f)  # the residual is always the displacement's
    np.testing.assert_allclose(K_same.toarray(), K.toarray(), rtol=0, atol=1e-9)
    # a tension larger by k 1e-3 on every stretched point adds its geometric part 2 W' I: positive, symmetric
    extra = (K_mixed - K).toarray()
    np.testing.assert_allclose(extra, extra.T, atol=1e-9)
    assert np.trace(extra) > 0.0


def _rest_stiffness(rule: str) -> FloatArray:
    """The thread's stiffness at rest (dense, on the wall faces' nodes' dofs only) under fibre ``rule``."""
    with fibre_rule(rule):
        mesh, fibres = _wall()
    _, K = fibres.force_and_tangent_at(np.zeros_like(mesh.points), want_tangent=True)
    assert K is not None
    dofs = (3 * np.unique(fibres.faces)[:, None] + np.arange(3)).ravel()
    return np.asarray(K[dofs][:, dofs].toarray())


def _hourglass_modes(one: FloatArray, six: FloatArray) -> FloatArray:
    """The modes (columns, on the wall's dofs) that the centroid's rest stiffness ``one`` misses and the six
    points' ``six`` sees: corners out, midsides in."""
    scale = np.linalg.eigvalsh(six)[-1]
    values, vectors = np.linalg.eigh(one)
    missed = vectors[:, values < ZERO_ENERGY * scale]  # the centroid's zero-energy modes
    seen, within = np.linalg.eigh(missed.T @ six @ missed)
    return np.asarray(missed @ within[:, seen > ZERO_ENERGY * scale])


def test_the_six_point_share_holds_the_centroids_hourglass_modes() -> None:
    """The centroid alone leaves modes that stretch the thread between a face's nodes but not at its centroid
    (corners out, midsides in: an hourglass); the solver's rule stores FIBRE_STABILISATION of the six points'
    energy in each of them, so that its zero-energy modes are only those of both rules (rigid and sliding
    motions of the wall, which stretch no thread anywhere)."""
    one, six, solver = (_rest_stiffness(r) for r in ("one-point", "six-point", "solver"))
    scale = np.linalg.eigvalsh(six)[-1]
    hourglass = _hourglass_modes(one, six)
    assert hourglass.shape[1] > 0  # the centroid does miss some that the six points see
    np.testing.assert_allclose(np.einsum("dm,de,em->m", hourglass, solver, hourglass),
                               FIBRE_STABILISATION * np.einsum("dm,de,em->m", hourglass, six, hourglass),
                               rtol=EXACT_RTOL * 1e3)  # both sums of some 1e2 terms of either sign
    rank = np.linalg.matrix_rank
    assert rank(solver, tol=ZERO_ENERGY * scale) == rank(one + six, tol=ZERO_ENERGY * scale)


def test_the_control_holds_in_a_buckled_thread_and_carries_no_tension() -> None:
    """Compressed past its buckling strain (the wall scaled radially by 0.9: e = -0.095), the thread's force is
    the buckled one, and the hourglass modes are still held: the control is a penalty on each point's departure
    from the centroid's strain, which does not buckle (a share of the thread's law at the six points would
    buckle with it and leave the mode free).  The thread's tension is the centroid's whatever the mode does."""
    one, six = _rest_stiffness("one-point"), _rest_stiffness("six-point")
    mode = _hourglass_modes(one, six)[:, -1]  # the one the six points hold most
    mesh, fibres = _wall()
    dofs = (3 * np.unique(fibres.faces)[:, None] + np.arange(3)).ravel()
    along = np.zeros(mesh.points.size)
    along[dofs] = mode
    along = along.reshape(-1, 3)
    stretch, e_b = 0.9, THREAD.buckling_strain(MATRIX_KPA)
    base = mesh.points * np.array([stretch - 1.0, stretch - 1.0, 0.0])
    step = 1e-4  # mm: a mode's strain of ~1e-4, small against the compression
    energies = [fibres.energy_at(base + k * step * along) for k in (-1, 0, 1)]
    curvature = (energies[0] - 2 * energies[1] + energies[2]) / step**2
    at_rest = FIBRE_STABILISATION * float(mode @ six @ mode)
    # the departures' gradient a D is the rest's A D scaled by about the stretch: stiffness ~0.81 of the rest's
    assert 0.5 * at_rest < curvature < at_rest
    moved = base + 0.05 * along
    centroid = fibres.strains_at(moved)[:, 0]
    assert np.all(centroid < -e_b)
    np.testing.assert_allclose(fibres.thread_tension_at(moved), -THREAD.axial_stiffness_mn * e_b, rtol=EXACT_RTOL)


def _caps(thread: HoopThread) -> tuple[QuadraticMesh, FibreMembrane]:
    """The quarter tube's top face as a chamber's cap (its normal along the axis z)."""
    points, tets = quarter_tube(INNER, OUTER, HEIGHT, (2, 4, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    faces = boundary_faces(mesh.linear.tets)
    top = quadratic_faces(mesh, faces[np.all(np.isclose(points[faces][..., 2], HEIGHT), axis=1)])
    axes = np.tile([0.0, 0.0, 1.0], (len(top), 1))
    return mesh, hoop_membrane(mesh.points, top, axes, np.full(len(top), INNER), thread, MATRIX_KPA)


def test_bare_caps_carry_no_thread_and_a_patch_two_families() -> None:
    """A cap stretched in its plane by lambda: a woven patch's two crossed families each strain by (lambda^2 - 1) / 2
    and store W = k e^2 / 2 per area each; bare caps store nothing."""
    patched = HoopThread(THREAD.pitch_mm, THREAD.diameter_mm, THREAD.modulus_kpa, patched_ends=True)
    assert len(_caps(THREAD)[1].faces) == 0
    mesh, fibres = _caps(patched)
    stretch = 1.05
    x = mesh.points * np.array([stretch - 1.0, stretch - 1.0, 0.0])
    e = (stretch**2 - 1) / 2
    np.testing.assert_allclose(fibres.strains_at(x), e, rtol=EXACT_RTOL * 1e2)  # mesh-sized sums of round-off
    half = len(fibres.faces) // 2
    assert np.array_equal(fibres.faces[:half], fibres.faces[half:])  # each cap face twice
    np.testing.assert_allclose(np.einsum("fqi,fqi->fq", fibres.reference[:half], fibres.reference[half:]), 0.0,
                               atol=EXACT_RTOL)  # crossed at right angles
    area = float(fibres.law_weights[:half].sum())
    # a quarter annulus of four chords (straight-sided elements): 4 (R^2 - r^2) sin(pi / 8) / 2
    np.testing.assert_allclose(area, 2 * (OUTER**2 - INNER**2) * np.sin(np.pi / 8), rtol=EXACT_RTOL)
    np.testing.assert_allclose(fibres.energy_at(x), 2 * patched.stiffness_mn_per_mm * e**2 / 2 * area,
                               rtol=EXACT_RTOL * 1e2)
