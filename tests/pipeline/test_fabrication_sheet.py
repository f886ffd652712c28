"""Issue 44, item 6: the fabrication sheet says how to make the body, every figure the build's (hand-made figures).

The whole-build checks (the actuator with its mould and chambers: fabrication.md is the sheet of the manifest's
figures, the report shows it) are in tests/e2e/test_one_story.py.
"""

from __future__ import annotations

import pytest

from softdesign.pipeline.fabrication_sheet import PRESS_FIT_FRACTION, WIRE_ASPECT_LIMIT, core_make, sheet_lines
from softdesign.pipeline.stages.fabrication import sheet_text
from softdesign.report.make_it import html_from_markdown

#: The rod model's reinforcement block (branch rod, issue 41) as the fabrication stage reads it.
REINFORCEMENT = {"kind": "hoop", "pitch_mm": 0.75,
                 "thread": {"name": "polyester 0.2", "diameter_mm": 0.2, "breaking_load_n": 9.5,
                            "source": "a thread's datasheet, table 1"},
                 "safety_factor": 3.0,
                 "windings": [{"section": 1, "chamber": 2, "turns": 31, "tension_per_turn_n": 0.42,
                               "tension_limit_n": 3.17}]}


def figures(**changes):
    base = {
        "name": "demo", "body_length_mm": 104.5,
        "material": {"name": "ecoflex-00-30", "source": "Smooth-On bulletin; unverified", "checked": False,
                     "mixing": "1A:1B by weight"},
        "mould": {"parts": [{"part": "half_a", "file": "meshes/mould/half_a.stl", "volume_mm3": 42737.0},
                            {"part": "core_plate", "file": "meshes/mould/core_plate.stl", "volume_mm3": 8102.0}],
                  "up": "base", "pour_mm": 4.5, "vent_mm": 2.5, "key_mm": 4.0, "clearance_mm": 0.2, "plate": True,
                  "cores": 1, "process": "removable", "note": "pull the plate and pins first",
                  "pull": {"half_a": [-0.8, -2e-16, 0.6], "half_b": [0.8, 0.0, -0.6]}},
        "cores": [{"name": "core_1_1", "segments": [
            {"what": "chamber", "diameter_mm": 0.8, "length_mm": 24.1, "make": core_make(0.8, 24.1)},
            {"what": "feed", "diameter_mm": 0.4, "length_mm": 1.6, "make": core_make(0.4, 1.6)}]}],
        "supply": {"count": 3, "diameter_mm": 0.4, "what": "one feed per chamber", "mode": None,
                   "design_pressure_kpa": None},
        "reinforcement": None,
    }
    return {**base, **changes}


@pytest.mark.parametrize(("diameter", "length", "make"), [
    (1.0, WIRE_ASPECT_LIMIT - 0.1, "printed"), (1.0, WIRE_ASPECT_LIMIT, "printed"),
    (1.0, WIRE_ASPECT_LIMIT + 0.1, "wire"), (0.8, 24.1, "wire"), (2.0, 30.0, "printed"),
])
def test_a_core_is_a_wire_only_above_the_stated_aspect_ratio(diameter, length, make):
    assert core_make(diameter, length) == make


def test_the_sheet_gives_every_part_in_order_with_the_builds_figures():
    text = sheet_text(figures())
    order = ["## Material", "## Mould parts", "## Assembly", "## Cores", "## Supply", "## Casting", "## Demoulding"]
    assert [text.index(h) for h in order] == sorted(text.index(h) for h in order)
    assert "mixing: 1A:1B by weight" in text and "104.5 mm long" in text
    assert "pour channel (4.5 mm)" in text and "vent (2.5 mm)" in text and "body's base up" in text
    assert "| core_1_1 | chamber | 0.80 | 24.1 | 30 | wire, 0.80 mm |" in text
    assert "| core_1_1 | feed | 0.40 | 1.6 | 4 | printed |" in text
    assert f"outer diameter {0.4 * (1 + PRESS_FIT_FRACTION):.2f} mm" in text
    # the core plate comes out before the halves open; the pull vectors are the build's, rounded, no "-0.000"
    demoulding = text[text.index("## Demoulding"):]
    assert demoulding.index("Pull the plate") < demoulding.index("Open the halves")
    assert "half a along [-0.800, 0.000, 0.600]" in demoulding and "Thread winding" not in text


def test_the_winding_is_in_the_sheet_when_the_actuation_gives_it_and_the_supply_says_its_pressure():
    supply = {"count": 12, "diameter_mm": 0.4, "what": "one feed per chamber", "mode": "single",
              "design_pressure_kpa": 23.25}
    text = sheet_text(figures(reinforcement=REINFORCEMENT, supply=supply))
    assert "hoop winding of polyester 0.2 (0.20 mm, breaking load 9.5 N: a thread's datasheet, table 1)" in text
    assert "pitch of 0.75 mm, safety factor 3" in text and "| 1 | 2 | 31 | 0.42 | 3.17 |" in text
    assert "supply: single at 23.2 kPa" in text or "supply: single at 23.3 kPa" in text
    assert "end patches" not in text  # the block has no ends (before round 4's patches) or bare ones alike
    assert "end patches" not in sheet_text(figures(reinforcement={**REINFORCEMENT, "ends": "bare"}))


def test_patched_chamber_ends_are_in_the_sheet_with_the_thread_and_pitch():
    text = sheet_text(figures(reinforcement={**REINFORCEMENT, "ends": "patch"}))
    winding = text[text.index("## Thread winding"):]
    assert "end patches: on each end of every chamber core" in winding
    assert "woven of polyester 0.2 in two crossed layers at the pitch (0.75 mm)" in winding


def test_without_a_mould_or_material_the_sheet_says_what_to_add():
    text = sheet_text(figures(mould=None, material=None, cores=[], supply=None))
    assert "No mould in the case (add `export.mould: {}`)" in text and "No material in the case" in text
    assert "## Casting" not in text and "## Cores" not in text


def test_the_report_shows_the_sheets_lines_as_html():
    page = html_from_markdown(sheet_lines(figures())[1:])
    assert "<h3>Cores</h3>" in page and "<th>core</th>" in page and "<td>wire, 0.80 mm</td>" in page
    assert "<ol>" in page and "<code>meshes/mould/half_a.stl</code>" in page and "---" not in page
