"""The feasibility verdict: one reason per cause, its worst place in mm from the base, every q it holds at."""

from __future__ import annotations

from softdesign.pipeline.feasibility_judge import judge, warnings_of

LIMITS = {"name": "ecoflex-00-30", "max_stretch": 5.5, "min_stretch": 0.7, "min_wall_mm": 1.0}


def _where(l, arc_mm, angle):
    return {"link": 0, "l": l, "arc_mm": arc_mm, "angle_deg": angle}


def _summary(per_q, morph_min):
    row = {"stretch_max": 1.2, "stretch_min": 1.0, "wall_min_mm": None}
    rows = []
    for q, low, where in per_q:
        rows.append({**row, "q": q, "stretch_min": low,
                     "where": {"stretch_max": _where(0.5, 50.0, 0.0), "stretch_min": where}})
    return {"per_q": rows, "morph": {"stretch_max": {"value": 1.2, "q": 1.0, "where": _where(0.5, 50.0, 0.0)},
                                     "stretch_min": morph_min}}


def test_one_cause_at_several_q_and_over_the_morph_is_one_reason_naming_the_worst():
    summary = _summary(
        [(0.0, 1.0, _where(0.1, 10.0, 0.0)), (0.5, 0.56, _where(0.0376, 3.9, 52.0)),
         (1.0, 0.11, _where(0.0386, 2.9, 61.0))],
        {"value": 0.105, "q": 0.981, "where": _where(0.0386, 2.8, 61.4)},
    )
    summary["per_q"][2]["stretch_max"] = 6.0  # a sourced limit crossed too: the verdict is its
    feasible, reasons, causes = judge(summary, LIMITS)
    assert feasible is False
    assert len(reasons) == 1 and reasons[0].startswith("skin stretch 6 > max_stretch 5.5") and len(causes) == 2
    # min_stretch has no source (materials.yaml): one cause, worded as a warning, not a reason
    (text,) = warnings_of(causes)
    assert text.endswith("(a rule of thumb without a source: a warning, not a verdict)")
    # the worst value (the morph search's), its place in mm from the base with link and angle, and every q
    assert text.startswith("skin stretch 0.105 < min_stretch 0.7 (ecoflex-00-30) at link 0, 2.8 mm from the base, "
                           "angle 61 deg (q = 0.981)")
    assert "export q = 0.5, 1" in text and "over the morph at q = 0.981" in text
    low = next(c for c in causes if c["limit_name"] == "min_stretch")
    assert low["export_q"] == [0.5, 1.0] and low["morph_q"] == [0.981]


def test_two_causes_are_two_reasons_and_within_limits_is_feasible():
    summary = _summary([(1.0, 0.5, _where(0.2, 20.0, 10.0))], {"value": 0.5, "q": 1.0, "where": _where(0.2, 20.0, 10)})
    summary["per_q"][0]["stretch_max"] = 6.0
    feasible, reasons, causes = judge(summary, LIMITS)
    assert feasible is False and len(reasons) == 1 and len(causes) == 2
    assert reasons[0].startswith("skin stretch 6 > max_stretch 5.5")
    assert len(warnings_of(causes)) == 1  # the min_stretch crossing
    ok = _summary([(1.0, 0.9, _where(0.2, 20.0, 10.0))], {"value": 0.9, "q": 1.0, "where": _where(0.2, 20.0, 10)})
    assert judge(ok, LIMITS) == (True, [], [])
    assert judge(ok, None) == (None, [], [])


def test_an_older_summary_without_mm_names_l():
    old = {"link": 1, "l": 0.25, "angle_deg": 90.0}
    summary = _summary([(1.0, 0.5, old)], {"value": 0.5, "q": 1.0, "where": old})
    _, _, causes = judge(summary, LIMITS)
    assert "at link 1, l = 0.2500, angle 90 deg" in warnings_of(causes)[0]
