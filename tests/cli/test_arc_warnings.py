"""Issue 14, item 2: the build and `pcc design` warn when one constant-curvature arc misses a link.

The demo's four equal links miss their best arcs by 1.9 to 2.8 mm at q = 1 (the
issue's "3.3 mm and 1 rad" is `pcc design`'s matched-point figure): every one
is above the stated 1 mm and each is named with its figure.  The links that
`softdesign design --tolerance-mm 1` chooses are all within it, and the build
agrees with the design on every link's figure.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.kinematics.arc_check import ARC_TOLERANCE_MM
from tests.helpers.paths import REPO

runner = CliRunner()
DEMO = REPO / "configs" / "demo.yaml"
#: blend: pcc's links against their best arcs at q = 1 (see the designed-demo test).
PCC_ARC_CHECK_MM = 0.1
FIGURE = re.compile(r"link (\d+): at q = 1 its centerline is up to ([0-9.]+) mm")


def test_the_demo_build_names_every_link_one_arc_misses_and_its_figure(tmp_path):
    result = runner.invoke(app, ["kinematics", str(DEMO), "--out", str(tmp_path / "build")])
    assert result.exit_code == 0, result.output
    manifest = json.loads((tmp_path / "build" / "manifest.json").read_text())
    check = manifest["metrics"]["kinematics"]["arc_check"]
    assert check["q"] == 1.0 and check["tolerance_mm"] == ARC_TOLERANCE_MM
    deviations = check["max_deviation_mm"]
    missed = [j for j, value in enumerate(deviations) if value > ARC_TOLERANCE_MM]
    assert missed == [0, 1, 2, 3]  # a 26 mm link of the tortuous demo is never within 1 mm of one arc
    warned = [(int(j), float(v)) for j, v in FIGURE.findall(result.stderr)]
    assert [j for j, _ in warned] == missed and len(check["warnings"]) == len(missed)
    np.testing.assert_allclose([v for _, v in warned], [deviations[j] for j in missed], rtol=5e-3)  # 3 digits
    # issue 44: each once, on stderr, with its stage; the same as the manifest's record, and not in the summary
    lines = [line for line in result.stderr.splitlines() if "q = 1" in line]
    assert all(line.startswith("  warning: kinematics: link") for line in lines) and len(lines) == len(missed)
    recorded = [w for w in manifest["warnings"] if w["code"] == "arc_misfit"]
    assert [w["place"] for w in recorded] == [f"link {j}" for j in missed]
    assert [f"  warning: kinematics: {w['text']}" for w in recorded] == lines
    assert "q = 1 its centerline" not in result.stdout


@pytest.mark.slow
def test_the_designed_demo_builds_without_a_warning_and_with_the_designs_figures(tmp_path):
    output = tmp_path / "designed.yaml"
    design = runner.invoke(app, ["design", str(DEMO), "--tolerance-mm", str(ARC_TOLERANCE_MM), "--out",
                                 str(tmp_path / "build"), "--output", str(output), "--json"])
    assert design.exit_code == 0, design.output
    links = json.loads(design.stdout)["links"]
    result = runner.invoke(app, ["kinematics", str(output), "--out", str(tmp_path / "designed")])
    assert result.exit_code == 0, result.output
    assert "warning" not in result.stderr
    check = json.loads((tmp_path / "designed" / "manifest.json").read_text())["metrics"]["kinematics"]["arc_check"]
    assert check["warnings"] == []
    # issue 30: the designed case builds blend: pcc, one link per section, each link at q = 1 one arc of the chain.
    # The check starts each arc on the spline's frame at the link's start; the quintic through the chain's samples
    # is within 1e-3 mm of the chain but its tangent at a joint, where the curvature jumps, is off by ~2e-3 rad, and
    # an arc started there drifts by that times the link's length (measured: 0.056 mm on the demo's 30 mm section)
    assert len(check["max_deviation_mm"]) == len(links)
    np.testing.assert_allclose(check["max_deviation_mm"], 0.0, rtol=0, atol=PCC_ARC_CHECK_MM)


def test_pcc_design_warns_above_warn_mm_only(tmp_path):
    args = ["pcc", "design", str(DEMO), "--d", "2", "--out", str(tmp_path / "build"), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    over = [(pose["q"], k["index"]) for pose in payload["poses"] for k in pose["links"]
            if k["backbone_max_mm"] > ARC_TOLERANCE_MM]
    assert over and len(payload["warnings"]) == len(over)
    for (q, j), line in zip(over, payload["warnings"], strict=True):
        assert line.startswith(f"q = {q:g}, link {j}: one constant-curvature arc misses the design by up to")
        assert f"warning: {DEMO}: {line}" in result.stderr
    quiet = runner.invoke(app, [*args, "--warn-mm", "100"])
    assert quiet.exit_code == 0 and json.loads(quiet.stdout)["warnings"] == [] and "arc misses" not in quiet.stderr
    bad = runner.invoke(app, [*args, "--warn-mm", "0"])
    assert bad.exit_code == 2 and "--warn-mm must be a finite number > 0 mm, got 0" in bad.stderr
