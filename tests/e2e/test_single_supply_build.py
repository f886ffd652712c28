"""configs/actuator.yaml, the demo as a single-supply device: the summary's figures, the table's pressures, the
thread's known answer, the verdict line at the end of the build and in the manifest (issue 41)."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.cases import case_from
from tests.helpers.paths import REPO

#: Whole builds: `make test-fast` leaves them out.
pytestmark = pytest.mark.slow

runner = CliRunner()
#: The sizing makes each section's summed bending (chambers and end walls) its designed turn to 1e-9 rad; the
#: series channels bend the end walls out of the section's plane, and rotations compose rather than add: the
#: section's composed turn differs by second order (the end wall's turn times the section's: 4.8e-5 rad measured).
TURN_ATOL_RAD = 1e-4
#: Values written to JSON and CSV and read back (repr floats): exact but for the last bit.
SAME_REL = 1e-12


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> tuple[Path, str]:
    folder = tmp_path_factory.mktemp("single")
    case = case_from(folder, REPO / "configs" / "actuator.yaml", {"export": {"q": [0.0, 0.5, 1.0]}})
    out = folder / "build"
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return out, result.stdout  # progress goes to stderr


def test_the_summary_gives_the_device(built: tuple[Path, str]) -> None:
    out, _ = built
    s = json.loads((out / "actuation" / "summary.json").read_text())
    assert (s["supply"], s["backbone"]) == ("single", "inextensible")
    p, e = s["design_pressure_kpa"], s["body_modulus_kpa"]
    assert p > 0 and e == pytest.approx(3 * 2 * 68.947572931683613 / 1.75 / 2, rel=SAME_REL)  # 3 mu, ecoflex-00-30
    r = s["reinforcement"]
    assert (r["kind"], r["pitch_mm"], r["safety_factor"], r["thread"]["name"]) == ("hoop", 0.5, 4.0, "kevlar-69")
    assert {"diameter_mm", "breaking_load_n", "source"} <= set(r["thread"])
    for section in s["sections"]:
        (chamber,) = section["chambers"]
        for key in ("angle_rad", "distance_mm", "diameter_mm"):
            assert set(chamber[key]) == {"start", "middle", "end"}
        # the thread's known answer: P r pitch on the widest turn
        assert chamber["diameter_max_mm"] >= max(chamber["diameter_mm"].values())
        radius = 0.5 * chamber["diameter_max_mm"]
        assert chamber["tension_per_turn_n"] == pytest.approx(p * radius * r["pitch_mm"] * 1e-3, rel=SAME_REL)
        assert chamber["tension_limit_n"] == pytest.approx(r["thread"]["breaking_load_n"] / 4.0, rel=SAME_REL)
        assert chamber["turns"] == math.ceil(chamber["length_mm"] / r["pitch_mm"])
        assert section["second_moment_mm4"] > 0
    # every section turns through its designed angle at P* (to second order in its end walls' turn)
    for section in s["sections"]:
        model, designed = section["model"], section["designed"]
        assert model["kappa"] * model["length"] == pytest.approx(designed["kappa"] * designed["length"],
                                                                 abs=TURN_ATOL_RAD)
    assert s["model_deviation_by_q_mm"]["0"] == pytest.approx(0.0, abs=1e-9)
    assert s["wall_min_mm"] >= s["material"]["min_wall_mm"]
    # the axis thread is not a cavity: two thread diameters from a cavity's surface, not min_wall_mm
    assert s["thread_gap_rule_mm"] == 2.0 * r["thread"]["diameter_mm"] <= s["thread_gap_min_mm"]
    assert s["feasible"] is True and s["reasons"] == []


def test_every_row_has_the_pressure_q_times_p_star(built: tuple[Path, str]) -> None:
    out, _ = built
    p = json.loads((out / "actuation" / "summary.json").read_text())["design_pressure_kpa"]
    with (out / "actuation.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert rows and all(float(r["pressure_kpa"]) == pytest.approx(float(r["q"]) * p, rel=SAME_REL, abs=0)
                        for r in rows)
    assert {r["chamber"] for r in rows} == {"1"}  # one chamber per section


def test_the_build_ends_on_the_device_verdict(built: tuple[Path, str]) -> None:
    out, output = built
    lines = output.strip().splitlines()
    assert lines[-1].startswith("build folder: ")
    last = lines[-2]  # the verdict's last margin: the device's line
    assert last.startswith("  + one pressure of ") and "mm (rod model), walls >= " in last
    assert "% of its limit" in last
    assert [line for line in lines if line.startswith("verdict: ")] == ["verdict: feasible for ecoflex-00-30"]
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["metrics"]["actuation"]["verdict_line"] == "device: " + last.removeprefix("  + ")
    assert manifest["verdict"]["margins"][-1] == last.removeprefix("  + ")


def test_the_chambers_are_one_cavity_joined_by_their_series_channels(built: tuple[Path, str]) -> None:
    from softdesign.io.formats import read_mesh
    from softdesign.meshing.checks import inspect_mesh

    out, _ = built
    s = json.loads((out / "actuation" / "summary.json").read_text())
    chambers, channels = s["layout"]["chambers"], s["layout"]["channels"]
    assert [c["section"] for c in channels] == [c["section"] for c in chambers[1:]]
    for channel, before, after in zip(channels, chambers, chambers[1:], strict=False):
        # from inside one chamber to inside the next, through the two end walls
        assert before["l_start"] < channel["l_start"] < before["l_end"] < after["l_start"] < channel["l_end"]
        assert channel["diameter_mm"] == s["spec"]["feed_diameter_mm"]
    for q in ("0.000", "0.500", "1.000"):  # one body, one cavity open at the base face: no closed void left
        report = inspect_mesh(*read_mesh(out / "meshes" / f"q_{q}.stl"))
        assert report.watertight and report.bodies == 1 and report.euler == 2, q
    assert min(w["thickness_mm"] for w in s["walls"] if w["kind"].startswith("channel-skin")) >= \
        s["material"]["min_wall_mm"]
