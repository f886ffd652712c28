"""The Newton matrices of one problem, factored in a nested-dissection order found once.

A section's Newton matrix (quadratic tetrahedra, about 18k unknowns on the
sample case's base section) is factored every Newton iteration, and the order
of its unknowns decides what that costs.  SuperLU's own orders on that matrix
(MMD on ``A^T + A``, COLAMD) left 20.7 M and 32.9 M entries in the factors and
took 7.0 s and 6.1 s; METIS's multilevel nested dissection (pymetis, MIT and
Apache-2.0) leaves 14.7 M and takes 1.4 s.  Every matrix of a problem has the
same sparsity, so :class:`TangentSolver` finds the order once (0.35 s) and
reuses it while the pattern stays the same.  METIS's seed is fixed: the same
matrix gets the same order, so a solve gives the same bytes each run.

Newton's matrices come whole (every unknown) and are factored on the free
unknowns in that order.  Slicing, converting and permuting each one cost a
quarter as much as its factorization on the sample device (about 0.35 s a
matrix of 20k unknowns, against 1.3 s); :meth:`TangentSolver.factor_free`
finds once per sparsity pattern where each entry of the factored matrix comes
from, and then gathers it: the same matrix, entry for entry.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pymetis
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from softdesign.types import FloatArray, IntArray

#: METIS's random seed (fixed: same order, same bytes).
METIS_SEED = 0


def nested_dissection(matrix: sp.csc_matrix) -> IntArray:
    """The fill-reducing order (n,) of a structurally symmetric ``matrix``: row/column ``order[i]`` goes to ``i``."""
    structure = sp.csr_matrix(matrix, copy=True)
    structure.data = np.ones_like(structure.data)
    pattern = sp.csr_matrix(structure + structure.T)  # symmetric by construction, whatever rounding left
    pattern.setdiag(0)
    pattern.eliminate_zeros()
    graph = pymetis.CSRAdjacency(pattern.indptr.astype(np.int32), pattern.indices.astype(np.int32))
    order, _ = pymetis.nested_dissection(graph, options=pymetis.Options(seed=METIS_SEED))
    return np.asarray(order, np.int64)


@dataclass(frozen=True)
class _Plan:
    """How a whole matrix of one pattern becomes the factored one: ``csc((data[take], indices, indptr))``, the
    free unknowns in ``order``; the pattern (``source_indptr``, ``source_indices``, ``free``) it was found for."""

    source_indptr: np.ndarray
    source_indices: np.ndarray
    free: np.ndarray
    take: IntArray
    indptr: np.ndarray
    indices: np.ndarray
    order: IntArray

    def fits(self, whole: sp.csr_matrix, free: np.ndarray) -> bool:
        """Whether ``whole`` and ``free`` have the pattern this plan was found for."""
        pairs = ((whole.indptr, self.source_indptr), (whole.indices, self.source_indices), (free, self.free))
        return all(len(a) == len(b) and np.array_equal(a, b) for a, b in pairs)


class TangentSolver:
    """Solves ``A x = b`` for the Newton matrices of one problem, each factored (SuperLU) in one kept order.

    Attributes
    ----------
    factorizations : how many matrices were factored
    orderings : how many orders were found (one per sparsity pattern)
    """

    def __init__(self) -> None:
        self._pattern: tuple[IntArray, IntArray] | None = None
        self._order: IntArray | None = None
        self._plan: _Plan | None = None
        self.factorizations = 0
        self.orderings = 0

    def factor(self, matrix: sp.csc_matrix) -> spla.LinearOperator:
        """The solver of ``matrix`` (csc, structurally symmetric) as an operator ``b -> x``."""
        matrix = sp.csc_matrix(matrix)
        matrix.sort_indices()
        order = self._order_of(matrix)
        return self._factored(matrix[order][:, order], order)

    def factor_free(self, whole: sp.csr_matrix, free: np.ndarray) -> spla.LinearOperator:
        """The solver of ``whole[free][:, free]`` (``whole`` (n, n) csr in canonical form, ``free`` (n,) bool) as
        an operator ``b -> x`` on the free unknowns: :meth:`factor`'s matrix, gathered by a plan kept per pattern."""
        plan = self._plan_of(whole, free)
        m = len(plan.indptr) - 1
        # copies: splu puts its matrix in canonical order in place, which must not reorder the plan's arrays
        gathered = sp.csc_matrix((whole.data[plan.take], plan.indices.copy(), plan.indptr.copy()), shape=(m, m))
        return self._factored(gathered, plan.order)

    def _factored(self, ordered: sp.csc_matrix, order: IntArray) -> spla.LinearOperator:
        """The solver ``b -> x`` of the matrix whose rows and columns ``order`` gives as ``ordered`` (factored as
        it stands: the order is already the fill-reducing one)."""
        lu = spla.splu(ordered, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        self.factorizations += 1

        def solve(rhs: FloatArray) -> FloatArray:
            x = np.empty_like(rhs)
            x[order] = lu.solve(rhs[order])
            return x

        n = ordered.shape[0]
        return spla.LinearOperator((n, n), matvec=solve, dtype=float)

    def _plan_of(self, whole: sp.csr_matrix, free: np.ndarray) -> _Plan:
        """Where each entry of the factored matrix comes from in ``whole.data``, found by taking :meth:`factor`'s
        steps on the pattern with each entry's position as its value (exact in float64 below 2^53 entries), so
        the gathered matrix is that one, entry for entry."""
        plan = self._plan
        if plan is not None and plan.fits(whole, free):
            return plan
        positions = sp.csr_matrix((np.arange(1, whole.nnz + 1, dtype=np.float64), whole.indices, whole.indptr),
                                  shape=whole.shape)
        matrix = sp.csc_matrix(positions[free][:, free])
        matrix.sort_indices()
        order = self._order_of(matrix)
        permuted = matrix[order][:, order]
        self._plan = _Plan(np.array(whole.indptr), np.array(whole.indices), np.array(free),
                           np.asarray(permuted.data, np.int64) - 1, np.asarray(permuted.indptr),
                           np.asarray(permuted.indices), order)
        return self._plan

    def _order_of(self, matrix: sp.csc_matrix) -> IntArray:
        pattern = (np.asarray(matrix.indptr, np.int64), np.asarray(matrix.indices, np.int64))
        same = self._pattern is not None and all(
            len(a) == len(b) and np.array_equal(a, b) for a, b in zip(pattern, self._pattern, strict=True))
        if not same or self._order is None:
            self._order = nested_dissection(matrix)
            self._pattern = pattern
            self.orderings += 1
        return self._order
