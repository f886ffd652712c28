"""The swept mesh's layer spacing: ``size_mm`` asked, halved only while the plan is not sound (issue 32)."""

from __future__ import annotations

import pytest

from softdesign.pipeline.stages.volume_layers import sound_layers


def test_sound_plan_keeps_the_size_asked():
    tried: list[float] = []
    assert sound_layers(4.0, 1.0, lambda s: tried.append(s) or s, lambda s: True) == 4.0
    assert tried == [4.0]


def test_unsound_plan_halves_down_to_the_floor():
    """A plan sound from 1.5 mm: 8 -> 4 -> 2 -> 1.5 (the floor caps the last halving, not 1)."""
    tried: list[float] = []
    got = sound_layers(8.0, 1.5, lambda s: tried.append(s) or s, lambda s: s <= 1.5)
    assert tried == [8.0, 4.0, 2.0, 1.5] and got == 1.5


def test_floor_plan_is_returned_even_if_unsound():
    """Below the floor nothing is tried: the stage's own checks then name the bad element."""
    tried: list[float] = []
    assert sound_layers(3.0, 1.0, lambda s: tried.append(s) or s, lambda s: False) == 1.0
    assert tried == [3.0, 1.5, 1.0]


def test_size_under_the_floor_is_planned_as_asked():
    assert sound_layers(0.5, 1.0, lambda s: s, lambda s: pytest.fail("not consulted at or under the floor")) == 0.5
