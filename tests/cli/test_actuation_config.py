"""The case file's actuation block: defaults, bounds and cross-checks refused by `softdesign validate` (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from tests.cli.test_cli_validate import demo_case

runner = CliRunner()


def test_defaults_are_documented_values(tmp_path: Path) -> None:
    case = load_case(demo_case(tmp_path, actuation={}))
    a = case.actuation
    assert a is not None
    assert (a.chambers_per_section, a.distance_mm, a.diameter_mm, a.feed_diameter_mm, a.end_wall_mm,
            a.first_angle_deg) == (3, 2.0, 0.8, 0.4, 1.0, 90.0)
    assert load_case(demo_case(tmp_path, name="plain")).actuation is None


@pytest.mark.parametrize(("actuation", "message"), [
    ({"distance_mm": 0}, "distance_mm"),
    ({"diameter_mm": -1}, "diameter_mm"),
    ({"end_wall_mm": 51}, "end_wall_mm"),
    ({"first_angle_deg": 400}, "first_angle_deg"),
    ({"chambers_per_section": 4}, "chambers_per_section"),
    ({"distance_mm": ".nan"}, "distance_mm"),
    ({"chamber_count": 3}, "chamber_count"),
    ({"feed_diameter_mm": 1.0}, "use feed_diameter_mm <= 0.8"),
    ({"distance_mm": 0.5, "diameter_mm": 0.9, "feed_diameter_mm": 0.3}, "overlap (centres 0.866 mm apart"),
    ({"distance_mm": 0.3, "diameter_mm": 0.7, "feed_diameter_mm": 0.3}, "reaches across the backbone"),
])
def test_bad_actuation_is_refused_naming_the_key(tmp_path: Path, actuation: dict, message: str) -> None:
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, actuation=actuation))])
    assert result.exit_code == 2, result.output
    assert "actuation" in result.stderr and message in result.stderr
    assert "Traceback" not in result.output


def test_actuation_and_a_hollow_wall_are_refused_together(tmp_path: Path) -> None:
    case = demo_case(tmp_path, actuation={}, export={"wall_mm": 0.5})
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 2 and "drop export.wall_mm" in result.stderr


def test_supply_reinforcement_and_backbone_defaults(tmp_path: Path) -> None:
    a = load_case(demo_case(tmp_path, actuation={})).actuation
    assert a is not None
    # per_chamber: a case written before the keys existed builds the device it describes
    assert (a.supply, a.backbone, a.reinforcement.kind, a.reinforcement.pitch_mm, a.reinforcement.thread.name,
            a.reinforcement.safety_factor) == ("per_chamber", "inextensible", "hoop", 0.5, "kevlar-69", 4.0)


@pytest.mark.parametrize(("actuation", "extra", "message"), [
    ({"supply": "single"}, {}, "add design: {tolerance_mm: 1} and blend: pcc"),
    ({"supply": "single", "diameter_mm": 1.0}, {"design": {"tolerance_mm": 1.0}, "blend": "pcc"},
     "supply: single sizes diameter_mm itself"),
    ({"supply": "single"}, {"design": {"tolerance_mm": 1.0}, "blend": "pcc", "export": {"volume_mesh": {}}},
     "export.volume_mesh does not take actuation.supply: single's tapered chambers"),
    ({"supply": "both"}, {}, "supply"),
    ({"backbone": "stiff"}, {}, "backbone"),
    ({"reinforcement": {"kind": "braid"}}, {}, "reinforcement.kind"),
    ({"reinforcement": {"pitch_mm": 0}}, {}, "pitch_mm"),
    ({"reinforcement": {"pitch_mm": 11}}, {}, "pitch_mm"),
    ({"reinforcement": {"safety_factor": 0.5}}, {}, "safety_factor"),
    ({"reinforcement": {"thread": {"name": "cotton"}}}, {}, "unknown thread 'cotton'; choose one of kevlar-69"),
    ({"reinforcement": {"thread": {"name": "kevlar-69", "diameter_mm": 1}}}, {}, "diameter_mm"),
])
def test_bad_supply_keys_are_refused_naming_the_key(tmp_path: Path, actuation: dict, extra: dict,
                                                    message: str) -> None:
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, actuation=actuation, **extra))])
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "Traceback" not in result.output


def test_single_supply_with_a_design_and_pcc_is_valid(tmp_path: Path) -> None:
    case = load_case(demo_case(tmp_path, actuation={"supply": "single"}, design={"tolerance_mm": 1.0}, blend="pcc"))
    assert case.actuation is not None and case.actuation.supply == "single"


def test_a_single_supply_takes_a_mould(tmp_path: Path) -> None:
    case = demo_case(tmp_path, actuation={"supply": "single"}, design={"tolerance_mm": 1.0}, blend="pcc",
                     export={"mould": {}})
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 0, result.output
