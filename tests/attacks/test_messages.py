"""Issue 36, messages that misled: each names the real cause now.

A centerline merely elsewhere than its surface got "a units mismatch would
explain it"; an initial radius or length of 1e-6 mm, and a radius or offset
of metres, failed late with advice about the mesher, the smoothing or the
end cut.
"""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import InputDataError
from softdesign.geometry.plausibility import check_surface_surrounds
from tests.helpers.attacks import assert_refused, demo_case

runner = CliRunner()


def _tube(radius: float = 3.0, length: float = 40.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A straight centerline with its radii and the vertices of a tube around it, mm."""
    z = np.linspace(0.0, length, 81)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    angles = np.linspace(0.0, 2 * np.pi, 32, endpoint=False)
    ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    vertices = np.array([[x, y, zz] for zz in z for x, y in ring])
    return points, np.full(len(z), radius), vertices


@pytest.mark.parametrize("with_radius", [True, False], ids=["radii", "no-radii"])
def test_a_centerline_elsewhere_gets_no_unit_hint(with_radius):
    points, radius, vertices = _tube()
    with pytest.raises(InputDataError) as err:
        # 2 m away: the surface scaled by 1000 (a 3 m tube) would contain it, yet units are not the cause
        check_surface_surrounds(points + [2000.0, 0.0, 0.0], radius if with_radius else None, vertices, "case.yaml")
    assert "units mismatch" not in str(err.value), str(err.value)
    assert "belong to the same vessel" in str(err.value)


def test_a_surface_in_metres_still_gets_the_unit_hint():
    points, radius, vertices = _tube()
    with pytest.raises(InputDataError, match="surface in m, centerline in mm"):
        check_surface_surrounds(points, radius, vertices / 1000.0, "case.yaml")


@pytest.mark.parametrize(
    ("section", "needles"),
    [
        ({"initial": {"kind": "straight", "radius_mm": 1e-6}}, ["initial.radius_mm", "0.03"]),
        ({"initial": {"kind": "straight", "length_mm": 1e-6}}, ["initial.length_mm", "5"]),
        ({"initial": {"kind": "straight", "radius_mm": 5000.0}}, ["initial.radius_mm", "100"]),
        ({"export": {"q": [0, 1], "offset_mm": 5000.0}}, ["export.offset_mm", "20"]),
    ],
    ids=["radius-1e-6", "length-1e-6", "radius-5-m", "offset-5-m"],
)
def test_sizes_no_actuator_can_have_are_refused_naming_the_key(tmp_path, section, needles):
    text = assert_refused(runner.invoke(app, ["validate", str(demo_case(tmp_path, **section))]), *needles)
    assert "mesher" not in text and "smoothing" not in text and "end_cut" not in text
