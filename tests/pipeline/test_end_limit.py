"""The single-supply design's warning when P* passes what a chamber's unreinforced end holds
(:func:`softdesign.pipeline.rod_actuation._end_notes`): a cavity in an incompressible neo-Hookean solid has no
equilibrium past 5 mu / 2."""

from __future__ import annotations

import pytest

from softdesign.pipeline.rod_actuation import END_LIMIT_MU, _end_notes, table_end_notes

#: Ecoflex 00-30's E = 3 mu, mu = 39.4 kPa (the material file's law).
YOUNG_KPA = 3 * 39.4


def test_the_cavity_limit_is_five_halves_of_mu() -> None:
    assert END_LIMIT_MU == pytest.approx(2.5)


def test_a_pressure_the_ends_hold_gives_no_warning() -> None:
    assert _end_notes(2.4 * 39.4, YOUNG_KPA, "bare") == []
    assert _end_notes(2.5 * 39.4, YOUNG_KPA, "bare") == []


def test_the_sample_devices_pressure_is_named_with_its_ratio_and_the_check() -> None:
    (note,) = _end_notes(446.6, YOUNG_KPA, "bare")
    assert "11.3 times the silicone's shear modulus (39.4 kPa)" in note
    assert "softdesign simulate CASE --all" in note and "actuation.reinforcement.ends: patch" in note


def test_patched_ends_get_no_closed_form_warning() -> None:
    # no closed form bounds a woven patch's hold: the whole-device finite elements are its check
    assert _end_notes(446.6, YOUNG_KPA, "patch") == []


def test_the_per_chamber_tables_highest_pressure_is_named_with_its_place() -> None:
    rows = [{"q": q, "section": 2, "chamber": c, "pressure_kpa": p}
            for q, c, p in ((0.5, 1, 90.0), (1.0, 1, 180.0), (1.0, 3, 1090.0), (0.0, 2, None))]
    (note,) = table_end_notes(rows, YOUNG_KPA, "bare")
    assert note.startswith("the table's highest pressure (section 2, chamber 3, q = 1) 1090.0 kPa is 27.7 times")
    assert table_end_notes(rows[:1], YOUNG_KPA, "bare") == []  # 90 kPa: 2.3 mu, under the limit
    assert table_end_notes(rows, None, "bare") == []  # no rod model (no material): no pressures to judge
    assert table_end_notes(rows, YOUNG_KPA, "patch") == []
