"""`softdesign simulate`: help, and bad options refused with exit 2 and the option named before any work."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import DEMO

runner = CliRunner()


def test_help_names_the_options() -> None:
    result = runner.invoke(app, ["simulate", "--help"])
    assert result.exit_code == 0
    for option in ("--section", "--pressures", "--feed-pressures", "--target", "--target-arc", "--json", "--timeout",
                   "--time-limit"):
        assert option in result.output


@pytest.mark.parametrize(("args", "message"), [
    (["--pressures", "10,20"], "expected 3"),
    (["--pressures", "10,x,0"], "is not a number"),
    (["--pressures", "10,2000,0"], "expected a number in [0, 1000]"),
    (["--pressures", "-1,0,0"], "expected a number in [0, 1000]"),
    (["--pressures", "10,0,0", "--target", "1"], "not several, not none"),
    ([], "not several, not none"),
    (["--target", "1", "--target-arc", "0.01,0,20"], "not several, not none"),
    (["--target-arc", "0.01,0"], "--target-arc: got 2 values"),
    (["--target-arc", "0.01,x,20"], "--target-arc value 2: 'x' is not a number"),
    (["--target-arc", "-0.01,0,20"], "--target-arc curvature (1/mm): got -0.01"),
    (["--target-arc", "0.01,0,0"], "--target-arc length (mm): got 0"),
    (["--target", "1.5"], "--target: got 1.5"),
    (["--pressures", "10,0,0", "--size-mm", "0"], "--size-mm: got 0"),
    (["--pressures", "10,0,0", "--timeout", "1e9"], "--timeout"),
    (["--pressures", "10,0,0", "--figure", "out.svg"], "expected a .png file"),
    (["--pressures", "10,0,0", "--figure", "no/such/folder/out.png"], "does not exist"),
    (["--pressures", "10,0,0", "--section", "0"], "numbered from 1 at the base"),
    (["--target", "1", "--time-limit", "700"], "not below --timeout 600 s"),
    (["--target", "1", "--time-limit", "0"], "--time-limit: got 0"),
    (["--pressures", "0,0,0", "--feed-pressures", "20,x"], "--feed-pressures value 2: 'x' is not a number"),
    (["--pressures", "0,0,0", "--feed-pressures", "20,-5"], "--feed-pressures value 2: got -5"),
    (["--pressures", "0,0,0", "--feed-pressures", "2000"], "expected a number in [0, 1000]"),
    (["--pressures", "0,0,0", "--feed-pressures", "nan"], "--feed-pressures value 1"),
    (["--target", "1", "--feed-pressures", "20"], "goes with --pressures"),
])
def test_bad_options_exit_2_before_any_work(args: list[str], message: str, tmp_path) -> None:
    result = runner.invoke(app, ["simulate", str(DEMO), "--out", str(tmp_path / "build"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not (tmp_path / "build").exists()  # refused before the build started


def test_the_figure_draws_a_payload(tmp_path) -> None:
    from softdesign.report.simulate_figures import simulate_figure_png

    z = np.linspace(0.0, 20.0, 11)
    payload = {"section": 0, "pressures_kpa": [10.0, 0.0, 0.0],
               "arc": {"kappa_per_mm": 0.01, "phi_rad": -1.5, "length_mm": 20.0},
               "deformed_centerline_mm": np.column_stack([0 * z, -0.005 * z**2, z]).tolist(),
               "convergence": [{"load_factor": 1.0, "residuals_mN": [1.0, 1e-3, 1e-9]}],
               "target": {"q": 1.0, "kappa_per_mm": 0.02, "phi_rad": -1.5, "length_mm": 20.0}}
    png = simulate_figure_png(payload)
    assert png.startswith(b"\x89PNG") and png == simulate_figure_png(payload)  # same figures, same bytes


@pytest.mark.slow
def test_feed_pressures_must_be_one_per_feed_crossing_the_section(tmp_path) -> None:
    """Refused (exit 2) before the mesh and the solve: the per-chamber demo's base section is crossed by the feeds
    of its three distal sections' chambers."""
    from tests.helpers.paths import REPO

    case = REPO / "configs" / "actuator-per-chamber.yaml"
    result = runner.invoke(app, ["simulate", str(case), "--out", str(tmp_path / "build"), "--pressures", "0,0,0",
                                 "--feed-pressures", "20"])
    assert result.exit_code == 2, result.output
    assert "got 1 values, section 1 has 9 feeds" in result.output
