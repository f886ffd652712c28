"""The least-squares system of the radius surface rho(l, a) = sum_ij C[i, j] B_i(l) P_j(a).

The design matrix of ``B_i(l_k) P_j(a_k)`` (16 nonzeros a row), its Gram matrix ``A^T A`` summed by dense blocks,
and the thin-plate roughness penalty over the developed wall; :mod:`softdesign.fitting.bspline_surface` solves
the system and splits the surface into links.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
import scipy.sparse as sp

from softdesign.fitting import bspline_basis as bb
from softdesign.types import FloatArray, IntArray


def design_matrix(knots: FloatArray, intervals: int, l: FloatArray, angle: FloatArray) -> sp.csr_matrix:
    """Sparse (n, n_l * M) matrix of ``B_i(l_k) P_j(a_k)``, column ``i * M + j``; 16 nonzeros a row."""
    return _design_csr(*_design_rows(knots, intervals, l, angle), len(knots) - bb.DEGREE - 1, intervals)


def design_and_gram(
    knots: FloatArray, intervals: int, l: FloatArray, angle: FloatArray
) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """:func:`design_matrix` A and ``A^T A``, the latter summed as dense (DEGREE + 1)^2-square blocks.

    The rows of points in the same knot span along l and around share all their columns, listed in
    the same order (the first names them), so each such group adds one dense block ``V^T V`` to the
    Gram matrix.  The sparse product's sums in another order (entries within 4e-15 of their size on the
    1M case), in a third of its time on the case's 500k points.  The blocks are summed by einsum, not
    BLAS: a threaded BLAS call for a large group stalls on a busy machine.
    """
    columns, values = _design_rows(knots, intervals, l, angle)
    count, width = values.shape
    order = np.argsort(columns[:, 0], kind="stable")
    first = columns[order, 0]
    starts = np.flatnonzero(np.diff(first, prepend=-1))  # columns are >= 0: the first row starts a group
    blocks = np.empty((len(starts), width, width))
    bounds = np.append(starts, count)
    for g, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        group = values[order[lo:hi]]
        np.einsum("ki,kj->ij", group, group, out=blocks[g])
    names = columns[order[starts]]
    rows = np.broadcast_to(names[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(names[:, None, :], blocks.shape).ravel()
    size = (len(knots) - bb.DEGREE - 1) * intervals
    gram = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(size, size))
    return _design_csr(columns, values, len(knots) - bb.DEGREE - 1, intervals), gram


def _design_rows(knots: FloatArray, intervals: int, l: FloatArray, angle: FloatArray) -> tuple[IntArray, FloatArray]:
    """Columns and values (n, (DEGREE + 1)^2) of each row of the design matrix, the open basis' index major."""
    il, vl = bb.open_local(knots, l)
    ia, va = bb.periodic_local(intervals, angle)
    k = bb.DEGREE + 1
    cols = (il[:, :, None] * intervals + ia[:, None, :]).reshape(-1, k * k)
    vals = (vl[:, :, None] * va[:, None, :]).reshape(-1, k * k)
    return cols, vals


def _design_csr(columns: IntArray, values: FloatArray, n_basis: int, intervals: int) -> sp.csr_matrix:
    count, width = values.shape
    # Every row holds width distinct columns (M >= 4), so the CSR arrays are written out directly.
    indptr = np.arange(0, width * count + 1, width, dtype=np.int64)
    return sp.csr_matrix((values.ravel(), columns.ravel(), indptr), shape=(count, n_basis * intervals))


def roughness_matrix(knots: FloatArray, intervals: int, ratio: float) -> sp.csr_matrix:
    """Penalty matrix P with ``c^T P c = (1/2pi) iint ratio^4 rho_ll^2 + 2 ratio^2 rho_la^2 + rho_aa^2 dl da``.

    ``ratio`` = r / L turns l derivatives into s derivatives at the penalty's scale r.
    """
    ll, la, aa = _roughness_terms(np.asarray(knots, float).tobytes(), int(intervals))
    energy = ratio**4 * ll + 2.0 * ratio**2 * la + aa
    return (energy / (2.0 * np.pi)).tocsr()


@functools.lru_cache(maxsize=2)
def _roughness_terms(knot_bytes: bytes, intervals: int) -> tuple[Any, Any, Any]:
    """The penalty's three Kronecker terms (ll, la, aa; sparse, as sp.kron gives them) for knots (float64 bytes) and M.

    Keyed on the knots' content: the hold-out's folds solve on one knot vector with different r
    (each training set's median rho), so the terms are built once, and only scaled per fold.
    The returned matrices are shared: callers combine them into new ones and never change them.
    """
    knots = np.frombuffer(knot_bytes, dtype=np.float64)
    breakpoints_l = np.unique(knots)
    breakpoints_a = np.linspace(0.0, 2.0 * np.pi, intervals + 1)

    def along(x, deriv):
        return bb.open_basis_matrix(knots, x, deriv)

    def around(x, deriv):
        return bb.periodic_basis_matrix(intervals, x, deriv)

    gl = [bb.gram_matrix(along, breakpoints_l, d) for d in range(3)]
    ga = [bb.gram_matrix(around, breakpoints_a, d) for d in range(3)]
    return sp.kron(gl[2], ga[0]), sp.kron(gl[1], ga[1]), sp.kron(gl[0], ga[2])
