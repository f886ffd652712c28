"""Strain and stress of a prescribed motion, element by element: the morph's 3D strain and what it costs.

The morph prescribes every material point's place at every q (no equilibrium
is solved), so each linear tetrahedron carries a constant deformation gradient
``F = dx dX^-1`` (edges at q over edges at q = 0, the cast state).  From it:

principal stretches
    lambda_i, square roots of the eigenvalues of ``C = F^T F`` (sorted
    descending); the largest principal Green strain is ``(lambda_1^2 - 1) / 2``.
Cauchy stress
    The laws of :mod:`softdesign.continuum.laws` (neo-Hookean, Yeoh) taken
    incompressible: ``sigma = 2 W'(I1_bar) B_bar - p I`` with ``B_bar =
    J^(-2/3) F F^T``.  The morph does not say p (it is what equilibrium would
    fix), so it is taken from a traction-free direction: ``n . sigma n = 0``
    with n the current direction of a given reference direction (through
    the wall: the wall's faces carry no load but the chamber's pressure,
    which is small against the stresses of a large stretch), or, when none is
    given, the direction of the least principal stretch.  In uniaxial
    tension ``F = diag(l, l^-1/2, l^-1/2)`` either gives ``sigma_11 = 2 W'
    (l^2 - 1/l)``: ``mu (l^2 - 1/l)`` for neo-Hookean (W' = mu / 2) and
    ``2 (l^2 - 1/l) (C1 + 2 C2 (I1 - 3) + 3 C3 (I1 - 3)^2)`` for Yeoh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.types import FloatArray, IntArray


def rest_inverses(rest: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """The inverse of every tetrahedron's edge matrix at rest, (T, 3, 3): computed once for every q.

    Raises
    ------
    ValueError
        A tetrahedron of zero volume at rest (no gradient is defined).
    """
    rest, tets = np.asarray(rest, float), np.asarray(tets, np.int64)
    edges0 = (rest[tets[:, 1:]] - rest[tets[:, :1]]).transpose(0, 2, 1)  # columns: edges
    cof = _cofactors(edges0)
    det = np.einsum("nij,nij->n", edges0, cof) / 3.0
    if np.any(np.abs(det) <= 1e-300):
        raise ValueError("deformation_gradients: a tetrahedron of zero volume at rest")
    return np.asarray(cof.transpose(0, 2, 1) / det[:, None, None], np.float64)


def deformation_gradients(rest: npt.ArrayLike, moved: npt.ArrayLike, tets: npt.ArrayLike,
                          inverses: FloatArray | None = None) -> FloatArray:
    """F of every tetrahedron, (T, 3, 3), from node positions at rest and moved (V, 3) mm.

    ``inverses`` (:func:`rest_inverses`) saves recomputing the rest state's for each moved state.
    """
    moved, tets = np.asarray(moved, float), np.asarray(tets, np.int64)
    inverse = rest_inverses(rest, tets) if inverses is None else inverses
    edges = (moved[tets[:, 1:]] - moved[tets[:, :1]]).transpose(0, 2, 1)
    return np.asarray(edges @ inverse, np.float64)  # matmul: batched 3 x 3 products faster than einsum


def _cofactors(M: FloatArray) -> FloatArray:
    """Cofactor matrices (n, 3, 3): columns the cross products of M's other two columns (det M = col . cof col)."""
    a, b, c = M[:, :, 0], M[:, :, 1], M[:, :, 2]
    return np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=2)


def symmetric_eigenvalues(A: npt.ArrayLike) -> FloatArray:
    """Eigenvalues (n, 3), descending, of symmetric 3 x 3 matrices (n, 3, 3), in closed form.

    The trigonometric solution of the characteristic cubic (Smith, Comm. ACM 4(4), 1961): with
    ``m = tr A / 3``, ``p^2 = |A - m I|^2 / 6`` and ``r = det((A - m I) / p) / 2``, the roots are
    ``m + 2 p cos(acos(r) / 3 + 2 pi k / 3)``.  Near a double root it loses half the digits (about 1e-8
    relative), which figures of stretch and stress do not notice; 10 to 20 times faster than eigvalsh.
    """
    A = np.asarray(A, float)
    m = np.trace(A, axis1=1, axis2=2) / 3.0
    off = A[:, 0, 1] ** 2 + A[:, 0, 2] ** 2 + A[:, 1, 2] ** 2
    d0, d1, d2 = A[:, 0, 0] - m, A[:, 1, 1] - m, A[:, 2, 2] - m
    p = np.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off) / 6.0)
    safe = np.where(p > 0.0, p, 1.0)
    det = (d0 * (d1 * d2 - A[:, 1, 2] ** 2) - A[:, 0, 1] * (A[:, 0, 1] * d2 - A[:, 1, 2] * A[:, 0, 2])
           + A[:, 0, 2] * (A[:, 0, 1] * A[:, 1, 2] - d1 * A[:, 0, 2]))
    phi = np.arccos(np.clip(0.5 * det / safe**3, -1.0, 1.0)) / 3.0
    first = m + 2.0 * p * np.cos(phi)
    last = m + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
    return np.asarray(np.column_stack([first, 3.0 * m - first - last, last]), np.float64)


def principal_stretches_3d(F: npt.ArrayLike) -> FloatArray:
    """(T, 3) principal stretches, descending, of deformation gradients (T, 3, 3)."""
    F = np.asarray(F, float)
    C = F.transpose(0, 2, 1) @ F
    return np.sqrt(np.maximum(symmetric_eigenvalues(C), 0.0))


def cauchy_stress(law: HyperelasticLaw, F: npt.ArrayLike, free: npt.ArrayLike | None = None) -> FloatArray:
    """Cauchy stress (T, 3, 3) kPa of the incompressible law, p from the traction-free direction (module notes).

    Parameters
    ----------
    law : the material's law (its bulk modulus is not used: incompressible)
    F : (T, 3, 3) deformation gradients
    free : (T, 3) reference directions that stay traction-free (normals of a plane of zero normal stress), or
        None: the direction of least principal stretch
    """
    F = np.asarray(F, float)
    cof = _cofactors(F)
    J = np.einsum("nij,nij->n", F, cof) / 3.0
    B_bar = J[:, None, None] ** (-2.0 / 3.0) * (F @ F.transpose(0, 2, 1))
    w1, _ = law.energy_derivatives(np.trace(B_bar, axis1=1, axis2=2))
    deviator = 2.0 * w1[:, None, None] * B_bar
    if free is None:
        normal_stress = symmetric_eigenvalues(deviator)[:, 2]  # B_bar's eigenvectors are the stretch directions
    else:
        n = (cof @ np.asarray(free, float)[:, :, None])[:, :, 0]  # a material plane's normal: F^-T N ~ cof(F) N
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        normal_stress = (n[:, None, :] @ deviator @ n[:, :, None])[:, 0, 0]
    return np.asarray(deviator - normal_stress[:, None, None] * np.eye(3), np.float64)


def principal_stresses(sigma: npt.ArrayLike) -> FloatArray:
    """(T, 3) principal values, descending, of symmetric stresses (T, 3, 3)."""
    return symmetric_eigenvalues(sigma)


@dataclass(frozen=True)
class ElementStrain:
    """Per tetrahedron at one q (or at several: every array then has a leading (Q,) axis).

    Attributes
    ----------
    stretches : (T, 3) principal stretches, descending
    green_max : (T,) largest principal Green strain
    stress_max : (T,) largest principal Cauchy stress, kPa (None without a law)
    """

    stretches: FloatArray
    green_max: FloatArray
    stress_max: FloatArray | None


@dataclass(frozen=True)
class RestState:
    """What every moved state's strain needs from the rest state, computed once (:func:`rest_state`).

    Attributes
    ----------
    tets : (T, 4) int64 node indices
    inverse : (3, 3, T) the inverse of each tetrahedron's rest edge matrix, component-major (contiguous per
        component, so that the per-q work is a few dozen whole-array products)
    free : (3, T) reference traction-free directions, or None (the least stretch's)
    """

    tets: IntArray
    inverse: FloatArray
    free: FloatArray | None


def rest_state(rest: npt.ArrayLike, tets: npt.ArrayLike, free: npt.ArrayLike | None = None,
               inverses: FloatArray | None = None) -> RestState:
    """The rest state of :func:`strains` from node positions at rest (V, 3) mm and ``free`` (T, 3) or None
    (``inverses``: :func:`rest_inverses`, when the caller has them)."""
    tets = np.asarray(tets, np.int64)
    inverses = rest_inverses(rest, tets) if inverses is None else inverses
    inverse = np.ascontiguousarray(np.asarray(inverses, float).transpose(1, 2, 0))
    directions = None if free is None else np.ascontiguousarray(np.asarray(free, float).T)
    return RestState(tets, inverse, directions)


#: Tetrahedra measured at once by :func:`strains`: its few dozen temporaries of this many float64 stay in the
#: processor's cache (the chambered demo's 543k tetrahedra: 0.14 s a q in chunks of 8192, 0.21 s whole).
STRAIN_CHUNK = 8192


def strains(state: RestState, moved: npt.ArrayLike, law: HyperelasticLaw | None) -> ElementStrain:
    """:func:`element_strain` of every tetrahedron at one or several moved states at once.

    ``moved`` is (V, 3) mm, or (Q, V, 3) for Q states: the arrays returned then have a leading (Q,) axis.
    Component by component on arrays of STRAIN_CHUNK values (tetrahedra times states: F, C = F^T F, its
    closed-form eigenvalues, det F): no batched 3 x 3 products, which numpy does an element at a time.  Each
    tetrahedron's figures are computed alone, so the chunks change no bit.
    """
    moved = np.asarray(moved, float)
    count, size = len(state.tets), max(1, STRAIN_CHUNK // int(np.prod(moved.shape[:-2], dtype=np.int64)))
    if count <= size:
        return _strains(state, moved, law)
    parts = [_strains(RestState(state.tets[k:k + size], state.inverse[:, :, k:k + size],
                                None if state.free is None else state.free[:, k:k + size]), moved, law)
             for k in range(0, count, size)]
    stress = None if law is None else np.concatenate([p.stress_max for p in parts if p.stress_max is not None],
                                                     axis=-1)
    return ElementStrain(np.concatenate([p.stretches for p in parts], axis=-2),
                         np.concatenate([p.green_max for p in parts], axis=-1), stress)


def _strains(state: RestState, moved: FloatArray, law: HyperelasticLaw | None) -> ElementStrain:
    """:func:`strains` on one chunk."""
    t = state.tets
    # edges[k][i]: component i of edge k (node k + 1 less node 0), each (..., T)
    coords = [moved[..., c][..., t] for c in range(3)]  # (..., T, 4) per coordinate
    edges = [[coords[i][..., k + 1] - coords[i][..., 0] for i in range(3)] for k in range(3)]
    inv = state.inverse
    F = [[edges[0][i] * inv[0, j] + edges[1][i] * inv[1, j] + edges[2][i] * inv[2, j] for j in range(3)]
         for i in range(3)]
    c = {(a, b): F[0][a] * F[0][b] + F[1][a] * F[1][b] + F[2][a] * F[2][b] for a, b in _UPPER}
    first, middle, last = _eigenvalues(c)
    squares = [np.maximum(v, 0.0) for v in (first, middle, last)]
    stretches = np.stack([np.sqrt(v) for v in squares], axis=-1)
    green = 0.5 * (squares[0] - 1.0)
    stress = None if law is None else _largest_stress_of(law, F, squares, state.free)
    return ElementStrain(stretches, green, stress)


_UPPER = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def _eigenvalues(c: dict[tuple[int, int], FloatArray]) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`symmetric_eigenvalues` on the six components of symmetric matrices, descending."""
    m = (c[0, 0] + c[1, 1] + c[2, 2]) / 3.0
    d0, d1, d2 = c[0, 0] - m, c[1, 1] - m, c[2, 2] - m
    off = c[0, 1] ** 2 + c[0, 2] ** 2 + c[1, 2] ** 2
    p = np.sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * off) / 6.0)
    safe = np.where(p > 0.0, p, 1.0)
    det = (d0 * (d1 * d2 - c[1, 2] ** 2) - c[0, 1] * (c[0, 1] * d2 - c[1, 2] * c[0, 2])
           + c[0, 2] * (c[0, 1] * c[1, 2] - d1 * c[0, 2]))
    phi = np.arccos(np.clip(0.5 * det / safe**3, -1.0, 1.0)) / 3.0
    first = m + 2.0 * p * np.cos(phi)
    last = m + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0)
    return first, 3.0 * m - first - last, last


def _largest_stress_of(law: HyperelasticLaw, F: list[list[FloatArray]], squares: list[FloatArray],
                       free: FloatArray | None) -> FloatArray:
    """The largest principal value of :func:`cauchy_stress` without forming it, on components.

    ``B_bar``'s eigenvalues are ``J^(-2/3) lambda_i^2`` (B and C share them), so ``sigma_1 = 2 W' J^(-2/3)
    (lambda_1^2 - m)`` with ``m`` the free direction's ``n . B n = |F^T n|^2`` (or lambda_3^2, the least
    stretch's); with ``n`` along ``cof(F) N`` that is ``J^2 |N|^2 / |cof(F) N|^2``, as ``F^T cof(F) = J I``.
    """
    cof = [[F[(i + 1) % 3][(j + 1) % 3] * F[(i + 2) % 3][(j + 2) % 3]
            - F[(i + 1) % 3][(j + 2) % 3] * F[(i + 2) % 3][(j + 1) % 3] for j in range(3)] for i in range(3)]
    J = F[0][0] * cof[0][0] + F[0][1] * cof[0][1] + F[0][2] * cof[0][2]
    scale = J ** (-2.0 / 3.0)
    w1, _ = law.energy_derivatives(scale * (squares[0] + squares[1] + squares[2]))
    if free is None:
        normal = squares[2]
    else:
        n = [cof[i][0] * free[0] + cof[i][1] * free[1] + cof[i][2] * free[2] for i in range(3)]
        normal = J * J * (free[0] ** 2 + free[1] ** 2 + free[2] ** 2) / (n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    return np.asarray(2.0 * w1 * scale * (squares[0] - normal), np.float64)


def element_strain(rest: FloatArray, moved: FloatArray, tets: IntArray, law: HyperelasticLaw | None,
                   free: FloatArray | None = None, inverses: FloatArray | None = None) -> ElementStrain:
    """Stretches, Green strain and (with a law) the largest principal stress of every tetrahedron.

    ``inverses`` (:func:`rest_inverses`) saves recomputing the rest state's; for many moved states make the
    rest state once with :func:`rest_state` and call :func:`strains`.
    """
    return strains(rest_state(rest, tets, free, inverses), moved, law)
