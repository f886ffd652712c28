"""The Newton matrices' solver: right answers in a nested-dissection order found once per sparsity pattern."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from softdesign.mechanics.linear_solve import TangentSolver, nested_dissection

#: Relative residual of a direct solve of a well-conditioned system.
SOLVE_RTOL = 1e-12


def _grid_laplacian(n: int, shift: float) -> sp.csc_matrix:
    """A 3D grid's Laplacian (n^3 unknowns) plus ``shift`` on the diagonal: symmetric, positive definite."""
    line = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    eye = sp.identity(n)
    grid = (sp.kron(sp.kron(line, eye), eye) + sp.kron(sp.kron(eye, line), eye) + sp.kron(sp.kron(eye, eye), line))
    return sp.csc_matrix(grid + shift * sp.identity(n**3))


def test_the_order_is_a_permutation_and_cuts_the_fill() -> None:
    matrix = _grid_laplacian(14, 0.1)
    order = nested_dissection(matrix)
    assert np.array_equal(np.sort(order), np.arange(matrix.shape[0]))
    ordered = spla.splu(sp.csc_matrix(matrix[order][:, order]), permc_spec="NATURAL", diag_pivot_thresh=0.0)
    natural = spla.splu(matrix, permc_spec="NATURAL", diag_pivot_thresh=0.0)
    assert ordered.L.nnz + ordered.U.nnz < 0.5 * (natural.L.nnz + natural.U.nnz)


def test_the_order_is_the_same_each_time() -> None:
    matrix = _grid_laplacian(10, 0.1)
    assert np.array_equal(nested_dissection(matrix), nested_dissection(matrix.copy()))


def test_solves_match_a_direct_solve_and_the_order_is_found_once_per_pattern() -> None:
    rng = np.random.default_rng(3)
    solver = TangentSolver()
    base = _grid_laplacian(8, 0.5)
    for k in range(3):  # same pattern, other values: one order
        matrix = sp.csc_matrix(base + sp.diags(rng.uniform(0.0, 1.0, base.shape[0])) * (k + 1))
        rhs = rng.standard_normal(base.shape[0])
        x = solver.factor(matrix).matvec(rhs)
        assert np.linalg.norm(matrix @ x - rhs) <= SOLVE_RTOL * np.linalg.norm(rhs)
        assert np.allclose(x, spla.spsolve(matrix, rhs), rtol=1e-10, atol=0.0)
    assert (solver.factorizations, solver.orderings) == (3, 1)
    other = _grid_laplacian(9, 0.5)  # another pattern: a new order
    solver.factor(other)
    assert solver.orderings == 2


def test_the_free_unknowns_matrix_is_gathered_entry_for_entry_each_time() -> None:
    # factor_free gathers the free unknowns' matrix by a plan kept per pattern: each new matrix of the pattern gives
    # exactly the solution of slicing and factoring it (the same bytes), also after splu has put an earlier
    # matrix in canonical order in place (it once reordered the plan's own arrays), and a new pattern a new plan
    rng = np.random.default_rng(5)
    base = sp.csr_matrix(_grid_laplacian(7, 0.5))
    free = rng.random(base.shape[0]) > 0.15
    solver, reference = TangentSolver(), TangentSolver()
    for k in range(3):
        matrix = base.copy()
        matrix.data = matrix.data * (1.0 + 0.1 * rng.random(matrix.nnz))
        matrix = sp.csr_matrix((matrix + matrix.T) / 2)
        rhs = rng.standard_normal(int(free.sum()))
        gathered = solver.factor_free(matrix, free).matvec(rhs)
        sliced = reference.factor(sp.csc_matrix(matrix[free][:, free])).matvec(rhs)
        assert np.array_equal(gathered, sliced), k
    assert solver.orderings == 1
    n, half = base.shape[0], base.shape[0] // 2
    wider = sp.csr_matrix(base + sp.eye(n, k=half) + sp.eye(n, k=-half))
    rhs = rng.standard_normal(int(free.sum()))
    np.testing.assert_allclose(wider[free][:, free] @ solver.factor_free(wider, free).matvec(rhs), rhs, rtol=0,
                               atol=SOLVE_RTOL * np.abs(rhs).max() * 1e3)
    assert solver.orderings == 2
