"""The default inlet: the clearly wider end of a path, else the other rules."""

from __future__ import annotations

import numpy as np

from softdesign.geometry.inlet import INLET_RATIO, end_radii, widest_end_flip
from softdesign.geometry.network import CenterlineNetwork, Orientation, Polyline, select_path

LINE = np.column_stack([np.zeros(101), np.zeros(101), np.linspace(0.0, 50.0, 101)])


def test_end_radii_average_the_last_tenth_of_the_path_at_each_end():
    radius = np.linspace(4.0, 2.0, 101)  # 4 -> 2 mm: the first 5 mm average 3.9, the last 5 mm 2.1
    first, last = end_radii(LINE, radius)
    assert np.isclose(first, 3.9) and np.isclose(last, 2.1)


def test_the_clearly_wider_end_is_the_inlet_whichever_way_the_file_runs():
    narrowing = np.linspace(4.0, 2.0, 101)
    flip, why = widest_end_flip(LINE, narrowing)
    assert not flip and "l = 0 at the widest end" in why and "3.9 mm" in why
    flip, _ = widest_end_flip(LINE[::-1], narrowing[::-1])
    assert flip


def test_ends_of_about_the_same_width_leave_the_choice_to_the_other_rules():
    almost = np.linspace(2.0, 0.99 * INLET_RATIO * 2.0, 101)
    assert widest_end_flip(LINE, almost) is None
    assert widest_end_flip(LINE, None) is None


def test_select_path_puts_l_0_at_the_wider_end_of_a_network_seeded_at_an_outlet():
    # two paths sharing their first points, as VMTK writes them when seeded at a narrow outlet
    shared = np.column_stack([np.zeros(21), np.zeros(21), np.linspace(0.0, 10.0, 21)])
    trunk = np.column_stack([np.zeros(40), np.zeros(40), np.linspace(10.5, 30.0, 40)])
    other = np.column_stack([np.linspace(0.5, 20.0, 40), np.zeros(40), np.full(40, 10.0)])
    lines = (np.concatenate([shared, trunk]), np.concatenate([shared, other]))
    radii = (np.concatenate([np.full(21, 1.5), np.full(40, 3.0)]), np.full(61, 1.5))
    network = CenterlineNetwork(tuple(Polyline(p, r) for p, r in zip(lines, radii, strict=True)), "t")
    path = select_path(network, 0, Orientation())
    assert np.array_equal(path.points[0], trunk[-1]) and "widest end" in path.notes[-1]
    # given final.inlet, the user's choice stands
    chosen = select_path(network, 0, Orientation(inlet=np.zeros(3)))
    assert np.array_equal(chosen.points[0], shared[0])
