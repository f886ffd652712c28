"""`softdesign kinematics` as DESIGN.md states it, on the sample case."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import REPO

runner = CliRunner()
DEMO = REPO / "configs" / "demo.yaml"
#: Composition of four 4x4 products of unit-norm rotations: round-off only.
COMPOSE_TOL = 1e-9


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "build"
    result = runner.invoke(app, ["kinematics", str(DEMO), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


def _pose(out: Path, q: str) -> dict:
    result = runner.invoke(app, ["kinematics", str(DEMO), "--out", str(out), "--q", q, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_json_has_exactly_the_documented_keys(built):
    payload = _pose(built, "0.5")
    assert list(payload) == ["q", "links", "base_to_tip", "frames"]
    assert payload["q"] == [0.5] * 4 and payload["frames"] == "rmf"
    for link in payload["links"]:
        assert list(link) == ["index", "l_start", "l_end", "length", "transform", "poe"]
        assert list(link["poe"]) == ["theta1", "xi1", "theta2", "omega"]
        assert np.asarray(link["transform"]).shape == (4, 4)


def test_equal_q_reproduces_the_blended_curve_end_to_end(built):
    from softdesign.config import load_case
    from softdesign.pipeline.stages.blend import load_blend

    shape = load_blend(built).shape
    assert load_case(DEMO).export.q_values() == [0.0, 0.5, 1.0]
    for q in (0.0, 0.3, 1.0):
        payload = _pose(built, str(q))
        poses = shape.curve_at(q).poses([0.0, 1.0])
        expected = np.linalg.inv(poses[0]) @ poses[1]
        np.testing.assert_allclose(payload["base_to_tip"], expected, rtol=0, atol=COMPOSE_TOL)


def test_one_q_per_link_composes_each_links_own_transform(built):
    mixed = _pose(built, "0.2,0.8,1,0.5")
    assert mixed["q"] == [0.2, 0.8, 1.0, 0.5]
    product = np.eye(4)
    for j, q in enumerate(mixed["q"]):
        alone = _pose(built, str(q))["links"][j]["transform"]
        np.testing.assert_allclose(mixed["links"][j]["transform"], alone, rtol=0, atol=COMPOSE_TOL)
        product = product @ np.asarray(alone)
    np.testing.assert_allclose(mixed["base_to_tip"], product, rtol=0, atol=COMPOSE_TOL)


def test_kinematics_json_is_kept_for_every_export_q(built):
    document = json.loads((built / "kinematics.json").read_text())
    assert [p["q"][0] for p in document["poses"]] == [0.0, 0.5, 1.0]
    assert "S_T_E = inv(F(q, l_start)) F(q, l_end)" in document["convention"]
    straight = document["poses"][0]["links"]
    assert all(link["poe"]["omega"] is None and link["poe"]["theta2"] == 0.0 for link in straight)


@pytest.mark.parametrize(
    ("q", "message"),
    [
        ("0.5,2", "value 2 of '0.5,2' is 2, expected a number in [0, 1]"),
        ("a", "'a' of 'a' is not a number"),
        ("0.1,0.2", "expected one value or 4 values"),
    ],
)
def test_bad_q_exits_2(built, q, message):
    result = runner.invoke(app, ["kinematics", str(DEMO), "--out", str(built), "--q", q])
    assert result.exit_code == 2
    assert message in result.output
