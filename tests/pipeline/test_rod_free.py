"""backbone: free's rest-length morph on known answers: its ends, the rod model's linear lengths, the l map."""

from __future__ import annotations

import numpy as np

from softdesign.pipeline.rod_free import l_from_s, morph_chain, s_from_l

#: Products and sums of a few exact numbers: rounding only.
EXACT_ATOL = 1e-12

W = np.array([[0.04, 0.0], [0.0, -0.02]])
LENGTHS = np.array([20.0, 30.0])
REST = np.array([18.0, 28.5])


def test_the_morph_runs_from_the_straight_rest_body_to_the_designed_chain():
    w0, l0 = morph_chain(W, LENGTHS, REST, 0.0)
    np.testing.assert_allclose(w0, 0.0, rtol=0, atol=EXACT_ATOL)
    np.testing.assert_allclose(l0, REST, rtol=0, atol=EXACT_ATOL)
    w1, l1 = morph_chain(W, LENGTHS, REST, 1.0)
    np.testing.assert_allclose(w1, W, rtol=0, atol=EXACT_ATOL)
    np.testing.assert_allclose(l1, LENGTHS, rtol=0, atol=EXACT_ATOL)


def test_at_q_each_section_is_the_rod_models_linear_length_and_turns_q_times_its_angle():
    eps = LENGTHS / REST - 1.0  # the mean strain at P*
    w, lengths = morph_chain(W, LENGTHS, REST, 0.3)
    np.testing.assert_allclose(lengths, REST * (1.0 + 0.3 * eps), rtol=0, atol=EXACT_ATOL)
    np.testing.assert_allclose(w * lengths[:, None], 0.3 * W * LENGTHS[:, None], rtol=0, atol=EXACT_ATOL)


def test_l_is_proportional_to_arc_length_within_each_section():
    breaks = np.array([0.0, 0.4, 1.0])
    l = np.array([0.0, 0.2, 0.4, 0.7, 1.0])
    s = s_from_l(breaks, REST, l)
    np.testing.assert_allclose(s, [0.0, 9.0, 18.0, 18.0 + 14.25, 46.5], rtol=0, atol=EXACT_ATOL)
    np.testing.assert_allclose(l_from_s(breaks, REST, s), l, rtol=0, atol=EXACT_ATOL)
