"""`softdesign simulate` on the per-chamber demo's first section with its hoop thread wound near-hoop (pitch
0.1 mm, 88 degrees from the chamber's axis): the solve converges, and one chamber's small pressure bends the section
away from it by the curvature issue 41's rod model gives that section.

The rod model is built from the same build folder the command used (its layout, its outlines, its E = 3 mu), its
feeds left solid as the section's mesh leaves them, and its chambers round as designed (the mesh's polygons have
the circles' areas).

Measured with the thread's energy at each wall face's centroid plus 5 % on six points
(:mod:`softdesign.mechanics.reinforcement`, "Integration"): 2.185e-4 against 2.246e-4 1/mm, -2.7 %.  At the
centroid alone it was -9.7 %: these chambers are 0.8-1.1 mm across in a 3 mm mesh (12 nodes round each), few wall
faces, where the centroid alone let the hoop go slack (six points alone gave -2.4 %).  So the bound is now the
issue's 5 %: it fails a solve that loses the thread (the bare section bends by (1 - 2 nu) of this, nearly nothing),
a rule that lets the hoop go slack again, or a rod model off by its chambers' areas.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow

runner = CliRunner()
CASE = REPO / "configs" / "actuator-per-chamber.yaml"
#: A winding near the rod model's pure hoop (its axial share cos(beta)^2 0.16 % rather than 3.8 % at 0.5 mm).
PITCH_MM = 0.1
#: Small against the chamber's stiffness: the linear range, where the rod model holds.
PRESSURE_KPA = 5.0
#: The issue's bound of the reinforced section against the rod model (measured -2.7 %: the module's docstring).
ROD_RTOL = 0.05
#: The bend's plane against "away from chamber 1" (the demo's section is curved and tapered), deg.
PHI_TOL_DEG = 10.0


def near_hoop_case(folder: Path) -> Path:
    """The demo's per-chamber case with its winding at PITCH_MM, written in ``folder`` (inputs by absolute path)."""
    import yaml

    case = yaml.safe_load(CASE.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((CASE.parent / case["final"][key]).resolve())
    case["actuation"]["reinforcement"] = {"pitch_mm": PITCH_MM}
    path = folder / "actuator-near-hoop.yaml"
    path.write_text(yaml.safe_dump(case))
    return path


def rod_kappa(case_file: Path, build_dir: Path, pressure_kpa: float) -> float:
    """Issue 41's rod model's curvature of section 1 with chamber 1 at ``pressure_kpa``, feeds solid, chambers round
    as designed, 1/mm."""
    from softdesign.kinematics.rod import Cavities, rod_body, section_arcs, station_poses, strains
    from softdesign.pipeline.api import build_through
    from softdesign.pipeline.rod_device import layout_stations, outlines_at, rod_setup, section_rest_lengths
    from softdesign.pipeline.stages.actuation import actuation_layout

    outcome = build_through(case_file, build_dir, "actuation")  # cached: the command built it
    setup = rod_setup(outcome.case)
    assert not isinstance(setup, str), setup
    kinematics = outcome.results["kinematics"]
    layout = actuation_layout(outcome.case, kinematics)
    assert layout is not None
    stations = layout_stations(layout, section_rest_lengths(kinematics))
    count = len(layout.chambers)
    centers, radii = np.zeros((len(stations.ds), count, 2)), np.zeros((len(stations.ds), count))
    for k, c in enumerate(layout.chambers):
        centers[:, k] = [c.distance_mm * math.cos(c.angle), c.distance_mm * math.sin(c.angle)]
        radii[(stations.section == c.section) & stations.chamber, k] = 0.5 * c.diameter_mm
    body = rod_body(stations.ds, stations.section, outlines_at(kinematics, outcome.results["fit"], stations.s),
                    Cavities(centers, radii, np.arange(count)), setup.modulus_kpa, setup.backbone)
    pressures = np.zeros(count)
    pressures[0] = pressure_kpa
    eps0, w, _ = strains(body, pressures)
    return float(section_arcs(body, station_poses(eps0, w, body.ds, np.eye(4)), eps0)[0][0])


def test_one_reinforced_chamber_bends_the_demo_section_as_the_rod_model(tmp_path: Path) -> None:
    out, case = tmp_path / "build", near_hoop_case(tmp_path)
    result = runner.invoke(app, ["simulate", str(case), "--out", str(out), "--section", "1",
                                 "--pressures", f"{PRESSURE_KPA:g},0,0", "--timeout", "3000", "--json"])
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert "hoop thread on the chamber walls" in payload["formulation"]
    assert payload["convergence"][-1]["load_factor"] == 1.0
    phi = math.degrees(payload["arc"]["phi_rad"])
    assert abs((phi - (90.0 + 180.0) + 180.0) % 360.0 - 180.0) < PHI_TOL_DEG  # chamber 1 lies at 90 deg
    np.testing.assert_allclose(payload["arc"]["kappa_per_mm"], rod_kappa(case, out, PRESSURE_KPA),
                               rtol=ROD_RTOL, atol=0)
