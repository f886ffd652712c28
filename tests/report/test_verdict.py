"""The report's first screen: the verdict, then its reasons, from hand-made manifests (no build)."""

from __future__ import annotations

from softdesign.report.verdict import build_verdict, verdict_html


def _manifest(**metrics):
    return {"metrics": metrics}


def test_an_infeasible_design_opens_with_not_feasible_and_its_first_cause():
    feasibility = {"feasible": False, "material": {"name": "ecoflex-00-30"},
                   "reasons": ["skin stretch 0.5 < min_stretch 0.7 (ecoflex-00-30) at link 0, 2.5 mm from the base",
                               "wall 0.4 mm < min_wall_mm 1 mm (ecoflex-00-30) at link 2, 40.1 mm from the base"]}
    verdict = build_verdict(_manifest(feasibility=feasibility))
    assert verdict.status == "infeasible"
    assert verdict.headline == f"NOT feasible: {feasibility['reasons'][0]}"
    assert verdict.reasons == (feasibility["reasons"][1],)
    page = verdict_html(verdict, "Checks: 93 of 93 passed.")
    # the verdict comes first, the tally after it
    assert page.index("NOT feasible") < page.index("Checks: 93 of 93 passed.")
    assert 'data-status="infeasible"' in page


def test_a_feasible_design_names_its_material_its_design_and_its_mould():
    manifest = _manifest(
        feasibility={"feasible": True, "material": {"name": "dragon-skin-10"}, "reasons": []},
        design={"chain_max_deviation_mm": 0.81, "tip_error_mm": 0.4},
        mould={"requested": True, "cavity": {"ok": True}, "disjoint": {"ok": True},
               "pull": {"half_a": {"ok": True}, "half_b": {"ok": True}}},
    )
    verdict = build_verdict(manifest)
    assert verdict.status == "feasible"
    assert verdict.headline.startswith("Feasible for dragon-skin-10; the composed design is within 0.81 mm")
    assert "the mould checks pass" in verdict.headline


def test_a_failed_mould_check_is_said():
    manifest = _manifest(feasibility={"feasible": True, "material": {"name": "x"}, "reasons": []},
                         mould={"requested": True, "cavity": {"ok": True}, "disjoint": {"ok": True},
                                "pull": {"half_a": {"ok": False}}})
    assert "the mould checks FAIL" in build_verdict(manifest).headline


def test_without_a_material_the_design_is_not_judged_and_the_line_says_how_to_judge_it():
    verdict = build_verdict(_manifest(feasibility={"feasible": None, "material": None, "reasons": ["no material"]}))
    assert verdict.status == "not judged" and "material:" in verdict.headline


def test_the_fits_warnings_are_named_in_the_verdict():
    held = "no wall seen all round over 30.0 mm at 0.0-30.0 mm from the inlet, longer than the local diameter 6.0 mm"
    manifest = _manifest(feasibility={"feasible": True, "material": {"name": "x"}, "reasons": []},
                         fit={"warnings": [held]})
    verdict = build_verdict(manifest)
    assert verdict.headline.endswith("but the fit does not match the vessel everywhere (below)")
    assert verdict.notes == (f"fit: {held}",)
    assert f"fit: {held}" in verdict_html(verdict, "Checks: 1 of 1 passed.")


def test_a_single_supply_device_says_what_one_pressure_does():
    line = ("device: one pressure of 852.5 kPa bends it into the vessel within 1.17 mm (rod model), walls >= 1.01 "
            "mm, thread at 0.9 % of its limit")
    manifest = _manifest(feasibility={"feasible": True, "material": {"name": "ecoflex-00-30"}, "reasons": []},
                         actuation={"feasible": True, "reasons": [], "verdict_line": line})
    verdict = build_verdict(manifest)
    assert verdict.status == "feasible"
    assert line.removeprefix("device: ") in verdict.headline and "device:" not in verdict.headline
