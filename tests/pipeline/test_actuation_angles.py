"""Issue 44, item 3: angles in actuation.csv and the layout's JSON are degrees in (-180, 180], one convention."""

from __future__ import annotations

import math

import pytest

from softdesign.pipeline.stages.actuation import degrees_wrapped


@pytest.mark.parametrize(("degrees", "expected"), [
    (390.0, 30.0), (420.0, 60.0), (0.0, 0.0), (-0.0, 0.0), (180.0, 180.0), (-180.0, 180.0), (540.0, 180.0),
    (-190.0, 170.0), (181.0, -179.0), (359.0, -1.0), (-720.0 + 45.0, 45.0),
])
def test_an_angle_is_wrapped_to_the_half_open_interval_and_written_without_float_noise(degrees, expected):
    wrapped = degrees_wrapped(math.radians(degrees))
    assert wrapped == expected  # exact: rounded to 1e-9 deg, so 390 - 360 is written as 30.0, never 29.99999999999994
    assert -180.0 < wrapped <= 180.0 and str(wrapped) != "-0.0"
