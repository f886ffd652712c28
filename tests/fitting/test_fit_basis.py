"""The 1-D cubic bases against scipy's independent B-splines, and their exact integrals."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from softdesign.fitting import bspline_basis as bb

#: Basis values are sums of a few O(1) products; derivatives scale with the knot spacing's inverse powers.
VALUE_TOL = 1e-13
#: d^3 of a cubic on intervals of 0.05 is ~1e4 in size; double rounding leaves ~1e-10 of it.
DERIV_TOL = 1e-9


def _scipy_open_basis(knots, x, deriv):
    count = len(knots) - bb.DEGREE - 1
    columns = []
    for i in range(count):
        spline = BSpline(knots, np.eye(count)[i], bb.DEGREE, extrapolate=False)
        columns.append(spline.derivative(deriv)(x) if deriv else spline(x))
    return np.nan_to_num(np.column_stack(columns))


@pytest.mark.parametrize("deriv", [0, 1, 2, 3])
def test_open_basis_matches_scipy(deriv):
    knots = bb.open_knots([0.0, 0.3, 1.0], [3, 5])
    x = np.concatenate([np.linspace(0.0, 1.0, 41), [0.3, 0.3 + 1e-12, 1.0]])
    mine = bb.open_basis_matrix(knots, x, deriv).toarray()
    ref = _scipy_open_basis(knots, x[:-1], deriv)  # scipy's last interval is open at 1
    np.testing.assert_allclose(mine[:-1], ref, rtol=0, atol=DERIV_TOL if deriv else VALUE_TOL)


def test_values_and_slopes_together_are_the_separate_ones():
    knots = bb.open_knots([0.0, 0.3, 1.0], [3, 5])
    x = np.linspace(0.0, 1.0, 57)
    index, values, slopes = bb.open_local_and_slope(knots, x)
    for deriv, together in ((0, values), (1, slopes)):
        alone_index, alone = bb.open_local(knots, x, deriv)
        np.testing.assert_array_equal(index, alone_index)
        np.testing.assert_array_equal(together, alone)
    angle = np.linspace(-7.0, 7.0, 61)
    index, values, slopes = bb.periodic_local_and_slope(7, angle)
    for deriv, together in ((0, values), (1, slopes)):
        alone_index, alone = bb.periodic_local(7, angle, deriv)
        np.testing.assert_array_equal(index, alone_index)
        np.testing.assert_array_equal(together, alone)


def test_open_knots_put_every_break_in_and_divide_links_evenly():
    knots = bb.open_knots([0.0, 0.3, 1.0], [3, 5])
    inner = knots[bb.DEGREE + 1 : -bb.DEGREE - 1]
    np.testing.assert_allclose(inner, [0.1, 0.2, 0.3, 0.44, 0.58, 0.72, 0.86], rtol=0, atol=VALUE_TOL)
    assert np.count_nonzero(knots == 0.3) == 1


@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_periodic_basis_matches_wrapped_scipy_spline(deriv):
    intervals = 8
    knots = bb.periodic_knots(intervals)
    angle = np.linspace(-7.0, 13.0, 57)
    mine = bb.periodic_basis_matrix(intervals, angle, deriv).toarray()
    wrapped = np.mod(angle, 2 * np.pi)
    for j in range(intervals):
        coef = (np.arange(intervals + bb.DEGREE) % intervals == j).astype(float)
        spline = BSpline(knots, coef, bb.DEGREE)
        ref = spline.derivative(deriv)(wrapped) if deriv else spline(wrapped)
        np.testing.assert_allclose(mine[:, j], ref, rtol=0, atol=DERIV_TOL)


def test_bases_sum_to_one_and_derivatives_to_zero():
    x = np.linspace(0.0, 1.0, 33)
    knots = bb.open_knots([0.0, 0.5, 1.0], [2, 3])
    np.testing.assert_allclose(bb.open_basis_matrix(knots, x).sum(axis=1), 1.0, rtol=0, atol=VALUE_TOL)
    np.testing.assert_allclose(bb.open_basis_matrix(knots, x, 2).sum(axis=1), 0.0, rtol=0, atol=DERIV_TOL)
    angle = np.linspace(-np.pi, np.pi, 33)
    np.testing.assert_allclose(bb.periodic_basis_matrix(5, angle).sum(axis=1), 1.0, rtol=0, atol=VALUE_TOL)


def test_gram_matrices_integrate_exactly():
    # Sum of all entries of G_d is the integral of (sum_i B_i^(d))^2: 1 on [0, 1] for d = 0, 0 for d > 0.
    knots = bb.open_knots([0.0, 0.4, 1.0], [2, 3])
    breakpoints = np.unique(knots)

    def along(x, deriv):
        return bb.open_basis_matrix(knots, x, deriv)

    assert bb.gram_matrix(along, breakpoints, 0).sum() == pytest.approx(1.0, abs=VALUE_TOL)
    assert bb.gram_matrix(along, breakpoints, 2).sum() == pytest.approx(0.0, abs=DERIV_TOL)
    # One entry by brute-force quadrature: integral of B_2'' B_3''.
    x = np.linspace(0.0, 1.0, 200001)
    values = along(x, 2).toarray()
    brute = np.trapezoid(values[:, 2] * values[:, 3], x)
    assert bb.gram_matrix(along, breakpoints, 2)[2, 3] == pytest.approx(brute, rel=1e-6)  # trapezoid error


def test_periodic_gram_of_values_sums_to_the_period():
    def around(x, deriv):
        return bb.periodic_basis_matrix(6, x, deriv)

    gram = bb.gram_matrix(around, np.linspace(0.0, 2 * np.pi, 7), 0)
    assert gram.sum() == pytest.approx(2 * np.pi, abs=VALUE_TOL)
    np.testing.assert_allclose(gram.toarray(), gram.toarray().T, rtol=0, atol=VALUE_TOL)


def test_knot_insertion_keeps_the_spline_and_leaves_inputs_alone():
    rng = np.random.default_rng(3)
    knots = bb.open_knots([0.0, 0.3, 1.0], [3, 5])
    coef = rng.random((len(knots) - bb.DEGREE - 1, 2))
    knots_before, coef_before = knots.copy(), coef.copy()
    new_knots, new_coef = knots, coef
    for _ in range(3):
        new_knots, new_coef = bb.insert_knot(new_knots, new_coef, 0.3)
    x = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(
        BSpline(new_knots, new_coef, bb.DEGREE)(x), BSpline(knots, coef, bb.DEGREE)(x), rtol=0, atol=VALUE_TOL
    )
    assert np.count_nonzero(new_knots == 0.3) == bb.DEGREE + 1
    np.testing.assert_array_equal(knots, knots_before)
    np.testing.assert_array_equal(coef, coef_before)


def test_no_points_give_empty_bases():
    knots = bb.open_knots([0.0, 1.0], [5])
    for values in (*bb.open_local_and_slope(knots, [])[1:], bb.open_local(knots, [], 1)[1],
                   *bb.periodic_local_and_slope(6, [])[1:], bb.periodic_local(6, [], 2)[1]):
        assert values.shape == (0, bb.DEGREE + 1)
