"""Issue 44: one record of a build's warnings and one verdict (softdesign/pipeline/notices.py), on known inputs."""

from __future__ import annotations

from softdesign.pipeline.notices import (
    NOTE,
    Judgement,
    Notice,
    notices_record,
    verdict_lines,
    verdict_record,
    warning_lines,
)

ARC = Notice("kinematics", "arc_misfit", "link 0", "link 0: 1.9 mm from its arc")
STRAY = Notice("fit", "centerline_stray", "", "the centerline strays 0.52 mm")
DONE = Notice("ingest", "note", "", "3 duplicate points removed", NOTE)


def test_each_notice_is_recorded_once_in_the_order_raised():
    record = notices_record([DONE, ARC, STRAY, ARC])
    assert [(r["stage"], r["code"], r["place"], r["kind"]) for r in record] == [
        ("ingest", "note", "", "note"), ("kinematics", "arc_misfit", "link 0", "warning"),
        ("fit", "centerline_stray", "", "warning")]


def test_the_terminal_lists_the_notes_then_the_warnings_and_nothing_when_there_are_none():
    assert warning_lines(notices_record([DONE, ARC, STRAY])) == [
        "note: ingest: 3 duplicate points removed", "2 warning(s):",
        "  warning: kinematics: link 0: 1.9 mm from its arc", "  warning: fit: the centerline strays 0.52 mm"]
    assert warning_lines([]) == []


def test_any_reason_makes_it_infeasible_a_material_without_one_feasible_and_neither_not_judged():
    skin = ("feasibility", Judgement(True, material="ecoflex-00-30"))
    chambers = ("actuation", Judgement(True, ("chambers: wall 0.4 mm < 1 mm",), material="ecoflex-00-30"))
    mould = ("mould", Judgement(False, margins=("the mould checks pass",)))
    assert verdict_record([skin, mould])["feasible"] is True
    record = verdict_record([skin, chambers, mould])
    assert (record["feasible"], record["status"], record["material"]) == (False, "NOT feasible", "ecoflex-00-30")
    assert verdict_lines(record) == ["verdict: NOT feasible for ecoflex-00-30: 1 reason(s)",
                                     "  - chambers: wall 0.4 mm < 1 mm", "  + the mould checks pass"]
    assert verdict_record([mould])["feasible"] is None and verdict_record([])["status"] == "not judged"
