"""The design stage's figures in `softdesign check` (softdesign.regression.sections, issue 35 item 2).

Manifests as the design stage writes ``metrics.design`` (figures of a real
demo build with ``design: {tolerance_mm: 1}``), compared by the table's row:
residuals within the smaller of the distance (angle) tolerance and rtol of
the reference plus a floor, joints within rtol, counts and flags exactly.
"""

from __future__ import annotations

import copy
import math

import pytest

from softdesign.regression import CheckOptions, Figure
from softdesign.regression.figures import RESIDUAL_FLOOR_DEG, RESIDUAL_FLOOR_MM
from softdesign.regression.sections import SECTIONS, compare_sections

OPTIONS = CheckOptions()
#: metrics.design of the demo designed at 1 mm (chain 0.468 mm, tip 0.135 mm and 1.51 deg off, five sections).
DESIGN = {"designed": True, "links": 5, "meets_tolerance": True, "chain_max_deviation_mm": 0.46772673908017404,
          "tip_error_mm": 0.1345699957577371, "tip_error_deg": 1.5072950931934528,
          "breaks": [0.0, 0.14508658805508237, 0.3542076984818114, 0.6433768477194515, 0.8568595387550719, 1.0]}
DESIGN_ROW = tuple(section for section in SECTIONS if section.item == "design")


def manifest(design: dict | None) -> dict:
    return {"metrics": {} if design is None else {"design": copy.deepcopy(design)}}


def compare(build: dict | None, reference: dict | None = DESIGN) -> tuple[list[Figure], list[str]]:
    notes: list[str] = []
    return compare_sections(manifest(build), manifest(reference), OPTIONS, notes, DESIGN_ROW), notes


def with_figure(name: str, value: object) -> dict:
    design = copy.deepcopy(DESIGN)
    design[name] = value
    return design


def failed(figures: list[Figure]) -> list[str]:
    return [f.figure for f in figures if not f.passed]


def test_the_design_row_reads_the_design_stages_block():
    assert [section.block for section in DESIGN_ROW] == ["design"]


def test_the_same_design_passes_with_every_figure_compared():
    figures, notes = compare(DESIGN)
    assert notes == [] and failed(figures) == []
    assert [f.figure for f in figures] == [
        "designed", "links", "meets_tolerance", *(f"breaks/{i}" for i in range(6)), "chain_max_deviation_mm",
        "tip_error_mm", "tip_error_deg"]


@pytest.mark.parametrize("name", ["chain_max_deviation_mm", "tip_error_mm", "tip_error_deg"])
def test_a_residual_moved_by_one_percent_fails_and_by_half_of_rtol_passes(name):
    # both far below the absolute tolerances (0.01 mm, 1e-4 rad = 0.0057 deg) for the two mm figures
    assert failed(compare(with_figure(name, DESIGN[name] * 1.01))[0]) == [name]
    assert failed(compare(with_figure(name, DESIGN[name] * (1 + 0.5 * OPTIONS.rtol)))[0]) == []


def test_a_large_residual_is_held_to_the_absolute_tolerance():
    # 50 mm off: rtol of it would allow 0.05 mm, the distance tolerance 0.01 mm is the smaller
    reference = with_figure("tip_error_mm", 50.0)
    assert failed(compare(with_figure("tip_error_mm", 50.02), reference)[0]) == ["tip_error_mm"]
    assert failed(compare(with_figure("tip_error_mm", 50.005), reference)[0]) == []
    reference = with_figure("tip_error_deg", 30.0)
    tolerance = math.degrees(OPTIONS.rotation_rad)
    assert failed(compare(with_figure("tip_error_deg", 30.0 + 2 * tolerance), reference)[0]) == ["tip_error_deg"]
    assert failed(compare(with_figure("tip_error_deg", 30.0 + 0.5 * tolerance), reference)[0]) == []


@pytest.mark.parametrize("name, floor", [("tip_error_mm", RESIDUAL_FLOOR_MM), ("tip_error_deg", RESIDUAL_FLOOR_DEG)])
def test_a_zero_residual_is_held_to_the_floor(name, floor):
    reference = with_figure(name, 0.0)
    assert failed(compare(with_figure(name, 0.5 * floor), reference)[0]) == []
    assert failed(compare(with_figure(name, 2.0 * floor), reference)[0]) == [name]


def test_a_joint_moved_by_one_percent_fails():
    breaks = list(DESIGN["breaks"])
    breaks[2] *= 1.01
    assert failed(compare(with_figure("breaks", breaks))[0]) == ["breaks/2"]


@pytest.mark.parametrize("name, value", [("links", 6), ("meets_tolerance", False), ("designed", False)])
def test_counts_and_flags_are_compared_exactly(name, value):
    assert name in failed(compare(with_figure(name, value))[0])


def test_a_section_more_fails_on_the_count_and_the_extra_joint():
    design = with_figure("links", 6)
    design["breaks"] = [*DESIGN["breaks"][:-1], 0.95, 1.0]
    figures = failed(compare(design)[0])
    assert "links" in figures and "breaks/6" in figures


def test_no_design_on_either_side_is_not_compared_and_said_so():
    figures, notes = compare({"designed": False}, {"designed": False})
    assert figures == [] and notes == ["design: not asked for on either side: not compared"]


def test_a_design_the_reference_has_and_the_build_lacks_fails():
    figures, _ = compare({"designed": False})
    assert {"designed", "links", "tip_error_mm", "chain_max_deviation_mm"} <= set(failed(figures))
    figures, _ = compare(None)
    assert failed(figures) == ["metrics.design"]


def test_a_reference_from_before_the_design_stage_is_noted_not_failed():
    figures, notes = compare(DESIGN, None)
    assert figures == [] and notes == ["the reference has no metrics.design (built before it existed): design not "
                                       "compared"]
