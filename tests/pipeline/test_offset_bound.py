"""An inward offset the vessel cannot take is refused before the fit (issue 35 item 5).

Known answers on a vessel of known inscribed radius (a straight path whose
radius narrows linearly), then the demo through the CLI: ``offset_mm: -3``
(its smallest inscribed radius is 2.944 mm, at the tip) used to fail at
export with exit 1 after the fit, and ``-10`` built an inside-out body with
exit 0; both now exit 2 after ingest, naming the place and the bound, and
leave no build folder.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import ConfigError
from softdesign.pipeline.offset_bound import check_offset
from tests.helpers.paths import REPO

runner = CliRunner()


def narrowing(offset_mm: float, wall_mm: float | None = None) -> tuple[SimpleNamespace, SimpleNamespace]:
    """A case's export block and a measured path: 101 points along z over 100 mm, radius 4 -> 2 mm (check_offset
    reads only these)."""
    z = np.linspace(0.0, 100.0, 101)
    path = SimpleNamespace(points=np.column_stack([np.zeros(101), np.zeros(101), z]), radius=4.0 - z / 50.0)
    case = SimpleNamespace(export=SimpleNamespace(offset_mm=offset_mm, wall_mm=wall_mm))
    return case, SimpleNamespace(path=path)


@pytest.mark.parametrize("offset_mm", [0.0, 1.0, -1.0, -1.999])
def test_an_offset_within_the_radius_passes(offset_mm):
    check_offset(*narrowing(offset_mm))


@pytest.mark.parametrize("offset_mm", [-2.0, -2.5, -10.0])
def test_an_offset_at_or_past_the_smallest_radius_is_refused_with_the_place_and_the_bound(offset_mm):
    with pytest.raises(ConfigError) as error:
        check_offset(*narrowing(offset_mm))
    message = str(error.value)
    assert message.startswith(f"export.offset_mm: {offset_mm:g} mm makes the body's radius {2.0 + offset_mm:.3f} mm")
    assert "at l = 1.0000 (100.0 mm from the inlet, point [0.0, 0.0, 100.0])" in message
    assert "inscribed radius is 2.000 mm" in message and "expected offset_mm > -2.000 mm" in message


def test_a_wall_that_leaves_no_chamber_is_refused_and_a_thinner_one_passes():
    check_offset(*narrowing(-0.5, wall_mm=1.4))
    expected = (r"export.wall_mm: 1.5 mm inside export.offset_mm -0.5 mm leaves the chamber a radius of 0.000 mm "
                r"at l = 1.0000 .* expected wall_mm - offset_mm < 2.000")
    with pytest.raises(ConfigError, match=expected):
        check_offset(*narrowing(-0.5, wall_mm=1.5))


def test_a_path_without_inscribed_radii_is_left_to_the_fit():
    case, ingest = narrowing(-10.0)
    ingest.path.radius = None
    check_offset(case, ingest)


@pytest.mark.slow
@pytest.mark.parametrize("offset_mm", [-3.0, -10.0])
def test_the_demo_with_too_large_an_inward_offset_exits_2_before_the_fit(tmp_path, offset_mm):
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text(encoding="utf-8"))
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"]["offset_mm"] = offset_mm
    (tmp_path / "demo.yaml").write_text(yaml.safe_dump(case), encoding="utf-8")
    result = runner.invoke(app, ["build", str(tmp_path / "demo.yaml"), "--out", str(tmp_path / "build")])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and "fit: running" not in result.output
    assert f"export.offset_mm: {offset_mm:g} mm makes the body's radius" in result.output
    assert "inscribed radius is 2.944 mm" in result.output and "expected offset_mm > -2.944 mm" in result.output
    assert not (tmp_path / "build").exists()
