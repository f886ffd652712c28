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
"""

from __future__ import annotations

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
        self.factorizations = 0
        self.orderings = 0

    def factor(self, matrix: sp.csc_matrix) -> spla.LinearOperator:
        """The solver of ``matrix`` (csc, structurally symmetric) as an operator ``b -> x``."""
        matrix = sp.csc_matrix(matrix)
        matrix.sort_indices()
        order = self._order_of(matrix)
        lu = spla.splu(matrix[order][:, order], permc_spec="NATURAL", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
        self.factorizations += 1

        def solve(rhs: FloatArray) -> FloatArray:
            x = np.empty_like(rhs)
            x[order] = lu.solve(rhs[order])
            return x

        n = matrix.shape[0]
        return spla.LinearOperator((n, n), matvec=solve, dtype=float)

    def _order_of(self, matrix: sp.csc_matrix) -> IntArray:
        pattern = (np.asarray(matrix.indptr, np.int64), np.asarray(matrix.indices, np.int64))
        same = self._pattern is not None and all(
            len(a) == len(b) and np.array_equal(a, b) for a, b in zip(pattern, self._pattern, strict=True))
        if not same or self._order is None:
            self._order = nested_dissection(matrix)
            self._pattern = pattern
            self.orderings += 1
        return self._order
