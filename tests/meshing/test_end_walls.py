"""How deep a tilted end cut reaches over the end chambers' discs (softdesign/meshing/chambers/end_walls.py), on
planes whose answer is written down: a tilt theta about B reaches (x + D/2) tan(theta) over a disc whose centre is
at x along N, and an offset along the outward tangent moves every depth by itself."""

from __future__ import annotations

import math

import numpy as np

from softdesign.meshing.chambers.end_walls import END_WALL_CLEARANCE_MM, end_leans, end_wall_problem
from softdesign.meshing.chambers.layout import ActuationSpec, plan_layout

#: Closed-form depths in float64: a few ulps of millimetres.
EXACT_MM = 1e-12

SPEC = ActuationSpec(distance_mm=2.0, diameter_mm=0.8, feed_diameter_mm=0.4, end_wall_mm=1.0, first_angle_deg=0.0)


def _layout(sections: int = 2):
    l = np.linspace(0.0, 1.0, 101)
    return plan_layout(SPEC, np.linspace(0.0, 1.0, sections + 1), l, 40.0 * l)


def test_a_square_cut_reaches_over_no_chamber():
    assert end_leans(_layout(), (None, None)) == []
    assert end_wall_problem(_layout(), (None, None), 1e-3) is None


def test_a_tilt_about_b_reaches_deepest_over_the_chamber_on_n():
    theta = math.radians(10.0)
    base = (math.sin(theta), 0.0, -math.cos(theta), 0.0)  # outward: against T, leaning towards +N
    leans = {e.chamber: e.lean_mm for e in end_leans(_layout(), (base, None))}
    # section 0's chambers at 0, 120, 240 degrees from N: x = d cos(beta)
    for j, beta in enumerate(np.radians([0.0, 120.0, 240.0])):
        expected = (2.0 * math.cos(beta) + 0.4) * math.tan(theta)
        np.testing.assert_allclose(leans[j], expected, rtol=0, atol=EXACT_MM)


def test_the_tip_cut_is_judged_over_the_last_sections_chambers_and_an_offset_moves_it():
    theta = math.radians(20.0)
    tip = (0.0, -math.sin(theta), math.cos(theta), 0.5)  # outward along T, leaning towards -B, 0.5 mm beyond the end
    leans = end_leans(_layout(3), (None, tip))
    assert {(e.end, e.section) for e in leans} == {("tip", 2)}
    layout = _layout(3)
    for e in leans:
        beta = layout.section_chambers(2)[e.chamber].angle
        expected = (-2.0 * math.sin(beta) + 0.4) * math.tan(theta) - 0.5
        np.testing.assert_allclose(e.lean_mm, expected, rtol=0, atol=EXACT_MM)


def test_the_refusal_names_the_end_wall_that_works_and_passes_it():
    theta = math.radians(10.0)
    base = (math.sin(theta), 0.0, -math.cos(theta), 0.0)
    deepest = (2.0 + 0.4) * math.tan(theta)  # 0.4232 mm over chamber 1
    works = math.ceil((deepest + END_WALL_CLEARANCE_MM) * 100.0) / 100.0
    problem = end_wall_problem(_layout(), (base, None), 0.3)
    assert problem is not None
    assert "chamber 1 of section 1" in problem and f"actuation.end_wall_mm: {works:g} or more" in problem
    assert end_wall_problem(_layout(), (base, None), works) is None
