"""`softdesign blend` says only what holds: shortening only when a shape between the ends is shorter."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.layout import BLEND_SUMMARY

from tests.helpers.paths import DEMO

runner = CliRunner()


def blend(case: Path, out: Path) -> tuple[list[str], dict]:
    """The blend stage's lines (as the CLI prints them) and its kept summary."""
    result = runner.invoke(app, ["blend", str(case), "--out", str(out)])
    assert result.exit_code == 0, result.output
    lines = result.stdout.split("[blend] ", 1)[1].splitlines()[1:4]
    return [line.strip() for line in lines], json.loads((out / BLEND_SUMMARY).read_text())


def demo(folder: Path, name: str, **sections) -> Path:
    """The sample case with absolute input paths and ``sections`` replaced."""
    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    case.update(sections, name=name)
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def test_a_linear_blend_of_equally_long_ends_reports_the_shorter_shape_between_them(tmp_path):
    lines, summary = blend(demo(tmp_path, "linear"), tmp_path / "out")
    sh = summary["shortening"]
    assert 0.4 < sh["q_at_min"] < 0.6 and sh["ratio"] > 0.01
    assert lines[2] == (f"shortest shape: {sh['min_length_mm']:.2f} mm at q = {sh['q_at_min']:.3f}, "
                        f"{100 * sh['ratio']:.3g}% shorter than the shorter end shape "
                        f"({sh['reference_length_mm']:.2f} mm)")


@pytest.mark.parametrize(
    "sections",
    [{"blend": "intrinsic"},  # lengths linear in q: every shape as long as the ends
     {"initial": {"kind": "straight", "length_mm": 50.0}},  # q = 0 is the shortest shape
     {"initial": {"kind": "straight", "length_mm": 200.0}}],  # q = 1 is
    ids=["intrinsic", "short_q0", "long_q0"],
)
def test_no_shortening_is_claimed_when_no_shape_between_the_ends_is_shorter(tmp_path, sections):
    lines, summary = blend(demo(tmp_path, "case", **sections), tmp_path / "out")
    initial, final = summary["initial_length_mm"], summary["final_path"]["length_mm"]
    assert lines[2] == (f"no intermediate shape is shorter than both end shapes "
                        f"(q = 0: {initial:.2f} mm, q = 1: {final:.2f} mm)")
    assert not any("% shorter" in line for line in lines)
