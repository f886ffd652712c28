"""The files' unit guessed from the vessel's size: one unit when only one fits, none when several or none do."""

from __future__ import annotations

import pytest

from softdesign.geometry.units_guess import guess_units


@pytest.mark.parametrize(("scale", "units"), [(1.0, "mm"), (0.001, "m")])
def test_an_aorta_in_mm_or_m_is_read_in_that_unit(scale, units):
    # the VMTK aorta's paths: 76-78 mm long, median inscribed radius about 5 mm
    guess = guess_units([77.8 * scale, 76.2 * scale], [5.4 * scale, 4.9 * scale])
    assert guess.units == units
    assert guess.plausible == (units,)
    assert len(guess.evidence) == 3 and any("a human vessel" in line for line in guess.evidence)


def test_an_aorta_in_cm_is_ambiguous_and_not_guessed():
    # 7.8 cm long with a 0.5 cm radius is also a human vessel read in mm (7.8 mm long, radius 0.5 mm)
    guess = guess_units([7.78, 7.62], [0.54, 0.49])
    assert guess.units is None and guess.plausible == ("mm", "cm")


def test_a_size_plausible_in_two_units_is_not_guessed():
    # 60 long with radius 2: a 60 mm artery of radius 2 mm, or a 600 mm vessel of radius 20 mm read in cm
    guess = guess_units([60.0], [2.0])
    assert guess.units is None
    assert guess.plausible == ("mm", "cm")


def test_a_size_no_unit_explains_is_not_guessed():
    guess = guess_units([1.0e9], [1.0])
    assert guess.units is None and guess.plausible == ()
    assert all("not a human vessel" in line for line in guess.evidence)


def test_without_radii_the_length_alone_decides():
    assert guess_units([1500.0], None).units == "mm"  # 15 m in cm, 1.5 km in m: only mm is human (5 mm to 2 m)
    assert guess_units([100.0], None).units is None  # 100 mm or 1 m: both human lengths


def test_mismatched_inputs_are_refused():
    with pytest.raises(ValueError, match="one length per path"):
        guess_units([1.0, 2.0], [1.0])
