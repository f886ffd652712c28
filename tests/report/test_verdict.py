"""The report's first screen: the manifest's one verdict, then its reasons and margins (hand-made manifests)."""

from __future__ import annotations

from html import escape

from softdesign.pipeline.notices import Judgement, verdict_record
from softdesign.report.tables import Check
from softdesign.report.verdict import OLDER_BUILD, build_verdict, checks_html, verdict_html

SKIN = "skin stretch 0.5 < min_stretch 0.7 (ecoflex-00-30) at link 0, 2.5 mm from the base"
WALL = "wall 0.4 mm < min_wall_mm 1 mm (ecoflex-00-30) at link 2, 40.1 mm from the base"


def test_an_infeasible_design_opens_with_not_feasible_then_every_reason_with_its_stage():
    record = verdict_record([("feasibility", Judgement(True, (SKIN,), material="ecoflex-00-30")),
                             ("actuation", Judgement(True, (f"chambers: {WALL}",), material="ecoflex-00-30"))])
    verdict = build_verdict({"verdict": record})
    assert verdict.status == "NOT feasible"
    assert verdict.headline == "NOT feasible for ecoflex-00-30: 2 reason(s)"
    assert verdict.reasons == (SKIN, f"chambers: {WALL}")
    page = verdict_html(verdict)
    assert 'data-status="NOT feasible"' in page and page.index("NOT feasible for") < page.index(escape(SKIN))


def test_a_feasible_design_names_its_material_and_its_margins():
    record = verdict_record([("design", Judgement(False, margins=("within 0.81 mm of the vessel",))),
                             ("feasibility", Judgement(True, material="dragon-skin-10")),
                             ("mould", Judgement(False, margins=("the mould checks pass",)))])
    verdict = build_verdict({"verdict": record})
    assert (verdict.status, verdict.headline) == ("feasible", "feasible for dragon-skin-10")
    assert verdict.margins == ("within 0.81 mm of the vessel", "the mould checks pass")
    assert verdict_html(verdict).count('class="margin"') == 2


def test_a_reason_without_a_material_still_makes_the_design_infeasible():
    record = verdict_record([("mould", Judgement(False, ("the mould cannot be used as drawn",)))])
    assert record["feasible"] is False and record["status"] == "NOT feasible"


def test_without_a_material_the_design_is_not_judged_and_the_line_says_how_to_judge_it():
    verdict = build_verdict({"verdict": verdict_record([("feasibility", Judgement(False))])})
    assert verdict.status == "not judged" and "material: {name:" in verdict.headline


def test_a_manifest_without_a_verdict_asks_for_a_new_build():
    assert build_verdict({"metrics": {}}).headline == OLDER_BUILD


def test_the_checks_tally_is_folded_and_opens_on_a_failure():
    ok = checks_html([Check("a.stl", "watertight", "yes", "yes", True)])
    assert ok.startswith('<details class="tally" id="checks">') and "Checks: 1 of 1 passed" in ok
    bad = checks_html([Check("a.stl", "watertight", "no", "yes", False)])
    assert 'id="checks" open>' in bad and "a.stl: watertight" in bad


def test_a_single_supply_device_says_what_one_pressure_does():
    from softdesign.pipeline.stages.judges import actuation_judgement

    line = ("device: one pressure of 852.5 kPa bends it into the vessel within 1.17 mm (rod model), walls >= 1.01 "
            "mm, thread at 0.9 % of its limit")
    summary = {"material": {"name": "ecoflex-00-30"}, "feasible": True, "reasons": [], "verdict_line": line}
    verdict = build_verdict({"verdict": verdict_record([("actuation", actuation_judgement(summary))])})
    assert verdict.status == "feasible" and verdict.margins == (line.removeprefix("device: "),)
    refused = {**summary, "feasible": False, "reasons": ["section 2: no chamber fits"],
               "verdict_line": "device: NOT feasible: section 2: no chamber fits"}
    verdict = build_verdict({"verdict": verdict_record([("actuation", actuation_judgement(refused))])})
    assert verdict.status == "NOT feasible"
    assert verdict.reasons == ("chambers: section 2: no chamber fits",) and verdict.margins == ()
