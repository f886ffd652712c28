"""One-dimensional cubic B-spline bases: knot vectors, basis values, Gram matrices, knot insertion.

Two kinds of knot vector are used by the surface fit:

* along the centerline (normalized l in [0, 1]): an *open* (clamped) vector
  with ``DEGREE + 1`` copies of 0 and 1, every link break as a simple knot
  and equal intervals inside each link;
* around it (angle a in [0, 2 pi)): a *periodic* uniform vector with
  ``M`` intervals, written out with ``DEGREE`` extra knots on each side so
  that the open-vector algorithms apply; basis index ``i`` is taken mod ``M``.

Only the ``DEGREE + 1`` basis functions that are nonzero at a point are ever
evaluated, so every matrix built from them is sparse.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from softdesign.types import FloatArray, IntArray

#: Cubic in both directions (C2 across simple knots).
DEGREE = 3
#: Points whose bases are found together: each point's are its own, and the temporaries of this many stay
#: in cache (500k points in one go took ~1.6 times as long).
BASIS_CHUNK = 1 << 15
#: Gauss-Legendre nodes per knot interval: exact for the degree-6 products in a Gram matrix.
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(4)


def open_knots(breaks: npt.ArrayLike, intervals: npt.ArrayLike) -> FloatArray:
    """Clamped knot vector on [0, 1] with each break a knot and equal intervals between breaks.

    Parameters
    ----------
    breaks : (J + 1,) float, strictly increasing from 0 to 1 (normalized l)
    intervals : (J,) int >= 1, knot intervals inside each [breaks[j], breaks[j + 1]]

    Returns
    -------
    (n + DEGREE + 1,) float, n = sum(intervals) + DEGREE basis functions
    """
    breaks = np.asarray(breaks, float)
    counts = np.asarray(intervals, int)
    pieces = [np.linspace(b0, b1, c + 1)[:-1] for b0, b1, c in zip(breaks[:-1], breaks[1:], counts, strict=True)]
    inner = np.concatenate(pieces)[1:]
    return np.concatenate([np.zeros(DEGREE + 1), inner, np.ones(DEGREE + 1)])


def periodic_knots(intervals: int) -> FloatArray:
    """Uniform knots ``(j - DEGREE) 2 pi / M``, j = 0 .. M + 2 DEGREE, for a periodic basis (rad)."""
    step = 2.0 * np.pi / intervals
    return (np.arange(intervals + 2 * DEGREE + 1, dtype=np.float64) - DEGREE) * step  # small integers: exact


def open_spans(knots: FloatArray, x: FloatArray) -> IntArray:
    """Knot span index ``s`` with ``knots[s] <= x < knots[s + 1]`` (x = 1 in the last span)."""
    last = len(knots) - DEGREE - 2
    return np.clip(np.searchsorted(knots, x, side="right") - 1, DEGREE, last).astype(np.int64)


def periodic_spans(intervals: int, angle: FloatArray) -> tuple[IntArray, FloatArray]:
    """Span index in :func:`periodic_knots` and the angle wrapped into [0, 2 pi)."""
    wrapped = np.mod(angle, 2.0 * np.pi)
    span = np.floor(wrapped * intervals / (2.0 * np.pi)).astype(np.int64)
    return np.clip(span, 0, intervals - 1) + DEGREE, wrapped


def nonzero_basis(knots: FloatArray, x: FloatArray, span: IntArray, deriv: int = 0) -> FloatArray:
    """Derivative ``deriv`` of the DEGREE + 1 basis functions nonzero in ``span``.

    Parameters
    ----------
    knots : (m,) float, nondecreasing
    x : (n,) float, parameter values inside their spans
    span : (n,) int, from :func:`open_spans` or :func:`periodic_spans`
    deriv : order of the derivative with respect to x

    Returns
    -------
    (n, DEGREE + 1) float; column r belongs to basis function ``span - DEGREE + r``.
    """
    if deriv > DEGREE:
        return np.zeros((len(x), DEGREE + 1))
    if len(x) > BASIS_CHUNK:
        return np.concatenate([nonzero_basis(knots, x[r], span[r], deriv) for r in chunks(len(x), BASIS_CHUNK)])
    values = _basis_values(knots, x, span, DEGREE - deriv)
    for degree in range(DEGREE - deriv, DEGREE):
        values = _raise_derivative(knots, values, span, degree)
    return np.ascontiguousarray(values.T)


def chunks(count: int, size: int) -> list[slice]:
    """Slices of ``size`` covering range(count), in order (one, possibly empty, when count <= size)."""
    return [slice(lo, lo + size) for lo in range(0, max(count, 1), size)]


# The triangles below hold one basis function per row, (functions, n): every step then reads and
# writes whole contiguous rows, where columns of (n, functions) arrays were strided.


def _basis_values(knots: FloatArray, x: FloatArray, span: IntArray, degree: int) -> FloatArray:
    """Cox-de Boor triangle: the degree + 1 nonzero functions of ``degree`` at ``span``, (degree + 1, n)."""
    left, right = _knot_distances(knots, x, span, degree)
    values = np.ones((1, len(x)))
    for j in range(1, degree + 1):
        values = _raise_degree(left, right, values, j)
    return values


def _knot_distances(knots: FloatArray, x: FloatArray, span: IntArray, degree: int) -> tuple[FloatArray, FloatArray]:
    """``x - knots[span + 1 - o]`` and ``knots[span + o] - x`` for o = 1 .. degree, each (degree, n).

    Every row of the Cox-de Boor triangle up to ``degree`` reads these; they are found once.
    """
    offsets = np.arange(1, degree + 1)[:, None]
    return x - knots[span + 1 - offsets], knots[span + offsets] - x


def _raise_degree(left: FloatArray, right: FloatArray, values: FloatArray, j: int) -> FloatArray:
    """One row of the Cox-de Boor triangle: the j + 1 functions of degree j from the j of degree j - 1."""
    new = np.zeros((j + 1, values.shape[1]))
    for r in range(j):
        temp = _divided(values[r], right[r] + left[j - r - 1])
        new[r] += right[r] * temp
        new[r + 1] = left[j - r - 1] * temp
    return new


def _divided(values: FloatArray, denom: FloatArray) -> FloatArray:
    """``values / denom``, 0 where denom is not > 0 (a repeated knot); the plain division when none is."""
    if denom.min(initial=np.inf) > 0:  # a NaN fails this too, and then gets the masked division's 0
        return values / denom
    return np.divide(values, denom, out=np.zeros(len(denom)), where=denom > 0)


def nonzero_basis_and_slope(knots: FloatArray, x: FloatArray, span: IntArray) -> tuple[FloatArray, FloatArray]:
    """Values and first derivatives (n, DEGREE + 1) of the basis functions nonzero in ``span``.

    The same numbers as ``nonzero_basis`` with deriv 0 and 1, sharing the
    lower-degree functions both are built from.
    """
    if len(x) > BASIS_CHUNK:
        pieces = [nonzero_basis_and_slope(knots, x[r], span[r]) for r in chunks(len(x), BASIS_CHUNK)]
        return np.concatenate([p[0] for p in pieces]), np.concatenate([p[1] for p in pieces])
    left, right = _knot_distances(knots, x, span, DEGREE)
    lower = np.ones((1, len(x)))
    for j in range(1, DEGREE):
        lower = _raise_degree(left, right, lower, j)
    values = _raise_degree(left, right, lower, DEGREE)
    return np.ascontiguousarray(values.T), np.ascontiguousarray(_raise_derivative(knots, lower, span, DEGREE - 1).T)


def _raise_derivative(knots: FloatArray, lower: FloatArray, span: IntArray, degree: int) -> FloatArray:
    """From the k-th derivative of the degree-``degree`` functions to the (k+1)-th of degree + 1, rows as above.

    Uses ``B'_{i,p+1} = (p+1) (B_{i,p} / (t_{i+p+1} - t_i) - B_{i+1,p} / (t_{i+p+2} - t_{i+1}))``.
    """
    p = degree
    # t_{i+p+1} - t_i for every i, read at i = span - p - 1 + r: one gather per row instead of two and a subtraction
    width = knots[p + 1 :] - knots[: -p - 1]
    out = np.zeros((p + 2, len(span)))
    for r in range(p + 2):
        if r >= 1:
            out[r] += _divided(lower[r - 1], width[span - p - 1 + r])
        if r <= p:
            out[r] -= _divided(lower[r], width[span - p + r])
    return (p + 1) * out


def open_local(knots: FloatArray, x: npt.ArrayLike, deriv: int = 0) -> tuple[IntArray, FloatArray]:
    """Indices (n, DEGREE + 1) and derivative values (n, DEGREE + 1) of the open basis nonzero at x."""
    x = np.asarray(x, float).reshape(-1)
    span = open_spans(knots, x)
    return span[:, None] - DEGREE + np.arange(DEGREE + 1), nonzero_basis(knots, x, span, deriv)


def periodic_local(intervals: int, angle: npt.ArrayLike, deriv: int = 0) -> tuple[IntArray, FloatArray]:
    """Indices (n, DEGREE + 1), mod M, and derivative values of the periodic basis nonzero at the angles."""
    angle = np.asarray(angle, float).reshape(-1)
    span, wrapped = periodic_spans(intervals, angle)
    values = nonzero_basis(periodic_knots(intervals), wrapped, span, deriv)
    # M >= 4 keeps the DEGREE + 1 indices of a row distinct.
    return np.mod(span[:, None] - DEGREE + np.arange(DEGREE + 1), intervals), values


def open_local_and_slope(knots: FloatArray, x: npt.ArrayLike) -> tuple[IntArray, FloatArray, FloatArray]:
    """Indices (n, DEGREE + 1), values and first derivatives of the open basis nonzero at x."""
    x = np.asarray(x, float).reshape(-1)
    span = open_spans(knots, x)
    return (span[:, None] - DEGREE + np.arange(DEGREE + 1), *nonzero_basis_and_slope(knots, x, span))


def periodic_local_and_slope(intervals: int, angle: npt.ArrayLike) -> tuple[IntArray, FloatArray, FloatArray]:
    """Indices (n, DEGREE + 1), mod M, values and first derivatives of the periodic basis at the angles."""
    angle = np.asarray(angle, float).reshape(-1)
    span, wrapped = periodic_spans(intervals, angle)
    values, slopes = nonzero_basis_and_slope(periodic_knots(intervals), wrapped, span)
    return np.mod(span[:, None] - DEGREE + np.arange(DEGREE + 1), intervals), values, slopes


def open_basis_matrix(knots: FloatArray, x: npt.ArrayLike, deriv: int = 0) -> sp.csr_matrix:
    """Sparse (n, n_basis) matrix of open-basis derivatives at x (normalized l)."""
    cols, values = open_local(knots, x, deriv)
    return _local_to_csr(cols, values, len(knots) - DEGREE - 1)


def periodic_basis_matrix(intervals: int, angle: npt.ArrayLike, deriv: int = 0) -> sp.csr_matrix:
    """Sparse (n, M) matrix of periodic-basis derivatives at the angles (rad)."""
    cols, values = periodic_local(intervals, angle, deriv)
    return _local_to_csr(cols, values, intervals)


def _local_to_csr(cols: IntArray, values: FloatArray, n_basis: int) -> sp.csr_matrix:
    rows = np.repeat(np.arange(len(cols)), cols.shape[1])
    return sp.csr_matrix((values.ravel(), (rows, cols.ravel())), shape=(len(cols), n_basis))


def gram_matrix(basis_at, breakpoints: FloatArray, deriv: int) -> sp.csr_matrix:
    """``G[i, j] = integral of B_i^(deriv) B_j^(deriv)`` over the breakpoints' range.

    Parameters
    ----------
    basis_at : callable (x, deriv) -> sparse (n, n_basis) basis matrix
    breakpoints : (m,) float, the distinct knots bounding the polynomial pieces
    deriv : derivative order

    Returns
    -------
    (n_basis, n_basis) sparse symmetric matrix; exact (4-point Gauss per piece).
    """
    lo, hi = breakpoints[:-1], breakpoints[1:]
    half = 0.5 * (hi - lo)
    nodes = (0.5 * (hi + lo))[:, None] + half[:, None] * _GAUSS_NODES[None, :]
    weights = (half[:, None] * _GAUSS_WEIGHTS[None, :]).ravel()
    values = basis_at(nodes.ravel(), deriv)
    return (values.T @ sp.diags(weights) @ values).tocsr()


def insert_knot(knots: FloatArray, coefficients: FloatArray, x: float) -> tuple[FloatArray, FloatArray]:
    """Insert ``x`` once into an open knot vector (Boehm); the spline is unchanged.

    Parameters
    ----------
    knots : (m,) float
    coefficients : (m - DEGREE - 1, ...) float; trailing axes are carried along
    x : the new knot, inside the domain; its multiplicity must stay <= DEGREE + 1

    Returns
    -------
    new knots (m + 1,), new coefficients (m - DEGREE, ...); inputs untouched.
    """
    span = int(np.searchsorted(knots, x, side="right") - 1)
    span = min(span, len(knots) - DEGREE - 2)
    out = np.empty((len(coefficients) + 1,) + coefficients.shape[1:])
    out[: span - DEGREE + 1] = coefficients[: span - DEGREE + 1]
    out[span + 1 :] = coefficients[span:]
    for i in range(span - DEGREE + 1, span + 1):
        alpha = (x - knots[i]) / (knots[i + DEGREE] - knots[i])
        out[i] = alpha * coefficients[i] + (1.0 - alpha) * coefficients[i - 1]
    return np.insert(knots, span + 1, x), out
