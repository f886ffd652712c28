"""Seed 003's improved-D-H rows in a designed build's outputs (issue 35 item 3).

The demo designed at 1 mm and built with ``blend: pcc`` through the
kinematics stage.  ``design/summary.json`` gives each section's five rows and
``kinematics.json`` each pose's sections at its q.  The rows are multiplied
here from elementary matrices (tests.helpers.seed_transforms), not with the
module, and compared with each section's HTM as the same build gives it
otherwise: ``inv(base frame) @ tip_frame`` of the design's chain, seed 003's
five steps at curvature q * kappa, and ``pcc forward --json`` given the
encoder lengths of the same arcs.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.kinematics import pcc
from softdesign.pipeline.api import build_through
from tests.helpers.cases import case_from
from tests.helpers.paths import DEMO
from tests.helpers.seed_transforms import dh_product, seed_chain

runner = CliRunner()
#: JSON doubles composed again by other code: round-off of a few products of 4x4 matrices with ~100 mm entries.
COMPOSE_TOL = 1e-9
#: Encoder spacing for `pcc forward`, mm: the arcs do not depend on it (seed eqs. 3-5), any d with every length > 0
#: (d kappa < 1: the demo's sections bend at most 0.2 /mm) gives them back.
D_MM = 2.0
COLUMNS = ("theta", "d", "a", "alpha")
#: Issue 35 item 4: a link's S_T_E (measured on the built centerline's frames) against its section's exact HTM.
JOINT_TOL_RAD = 1e-4
JOINT_TOL_MM = 1e-4


@pytest.fixture(scope="module")
def build(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("pcc_dh")
    case = case_from(folder, DEMO, {"design": {"tolerance_mm": 1.0}, "blend": "pcc"})
    build_through(case, folder / "build", target="kinematics")
    return folder / "build"


def read(build: Path, name: str) -> dict:
    return json.loads((build / name).read_text(encoding="utf-8"))


def table(rows: list[dict]) -> list[list[float]]:
    assert [list(row) for row in rows] == [list(COLUMNS)] * 5
    return [[row[c] for c in COLUMNS] for row in rows]


def forward(sections: list[dict]) -> dict:
    """`pcc forward --json` of the encoder lengths (seed eq. 2) of these sections' arcs."""
    lengths = pcc.lengths_from_arcs(*(np.array([s[k] for s in sections]) for k in ("kappa", "phi", "length")), D_MM)
    text = ";".join(",".join(repr(float(v)) for v in row) for row in lengths)
    result = runner.invoke(app, ["pcc", "forward", "--lengths", text, "--d", str(D_MM), "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_the_design_summarys_rows_multiply_to_each_sections_htm(build):
    design = read(build, "design/summary.json")
    assert "Rz(theta) Tz(d) Tx(a) Rx(alpha)" in design["dh_convention"]
    assert len(design["links"]) > 1  # a chain: every section after the first starts on the previous tip
    base = np.array(design["base_frame"])
    for link in design["links"]:
        tip = np.array(link["tip_frame"])
        table(link["dh"])
        np.testing.assert_allclose(dh_product(link["dh"]), np.linalg.inv(base) @ tip, rtol=0, atol=COMPOSE_TOL)
        base = tip


def test_the_kinematics_rows_are_each_sections_arc_at_q_and_multiply_to_its_htm(build):
    design, kinematics = read(build, "design/summary.json"), read(build, "kinematics.json")
    assert "pcc_sections" in kinematics["pcc_convention"]
    assert [pose["q"][0] for pose in kinematics["poses"]] == [0.0, 0.5, 1.0]  # the demo's export q
    for pose in kinematics["poses"]:
        sections = pose["pcc_sections"]
        assert [s["index"] for s in sections] == [link["index"] for link in pose["links"]]
        for section, link in zip(sections, design["links"], strict=True):
            q = section["q"]
            assert section["length"] == link["length"] and section["kappa"] == pytest.approx(q * link["kappa"])
            product = dh_product(section["dh"])
            np.testing.assert_allclose(product, section["transform"], rtol=0, atol=COMPOSE_TOL)
            np.testing.assert_allclose(product, seed_chain(q * link["kappa"], link["phi"], link["length"]),
                                       rtol=0, atol=COMPOSE_TOL)
    # q = 1: the design's own sections (its tip frames); q = 0: straight, a translation by L along z
    first, last = kinematics["poses"][0]["pcc_sections"], kinematics["poses"][-1]["pcc_sections"]
    assert [s["dh"] for s in last] == [link["dh"] for link in design["links"]]
    for section in first:
        straight = np.eye(4)
        straight[2, 3] = section["length"]
        np.testing.assert_allclose(dh_product(section["dh"]), straight, rtol=0, atol=COMPOSE_TOL)


@pytest.mark.parametrize("pose", [1, 2], ids=["q=0.5", "q=1"])
def test_the_rows_agree_with_pcc_forward_for_the_same_sections(build, pose):
    sections = read(build, "kinematics.json")["poses"][pose]["pcc_sections"]
    payload = forward(sections)
    for section, theirs in zip(sections, payload["sections"], strict=True):
        np.testing.assert_allclose(table(section["dh"]), table(theirs["dh"]), rtol=0, atol=COMPOSE_TOL)
        np.testing.assert_allclose(section["transform"], theirs["transform"], rtol=0, atol=COMPOSE_TOL)
    if pose == 2:  # the whole chain: pcc forward's tip in the design's base frame
        design = read(build, "design/summary.json")
        tip2base = np.linalg.inv(design["base_frame"]) @ np.array(design["links"][-1]["tip_frame"])
        np.testing.assert_allclose(payload["transform"], tip2base, rtol=0, atol=COMPOSE_TOL)


def link_errors(kinematics: dict) -> list[tuple[float, float, float]]:
    """Per pose: its q, and the largest rotation (rad) and translation (mm) from a link's transform to its section's."""
    out = []
    for pose in kinematics["poses"]:
        angle = distance = 0.0
        for link, section in zip(pose["links"], pose["pcc_sections"], strict=True):
            measured, exact = np.array(link["transform"]), np.array(section["transform"])
            cos = 0.5 * (np.trace(measured[:3, :3].T @ exact[:3, :3]) - 1.0)
            angle = max(angle, float(np.arccos(np.clip(cos, -1.0, 1.0))))
            distance = max(distance, float(np.linalg.norm(measured[:3, 3] - exact[:3, 3])))
        out.append((pose["q"][0], angle, distance))
    return out


def test_each_links_transform_is_its_sections_exact_htm_at_every_q(build):
    """The sections' joints are kept (each section its own spline, every break a sample): before they were,
    the corners were rounded, 0.21 mm and 0.0127 rad off at q = 1 (0.12 mm, 0.0064 rad at q = 0.5)."""
    errors = link_errors(read(build, "kinematics.json"))
    assert [q for q, _, _ in errors] == [0.0, 0.5, 1.0]
    for q, angle, distance in errors:
        assert angle <= JOINT_TOL_RAD and distance <= JOINT_TOL_MM, f"q = {q}: {angle:.3g} rad, {distance:.3g} mm"


def test_the_joints_are_kept_at_a_coarser_resampling(tmp_path):
    """At 1 mm samples the rounded corners were 0.36 mm and 0.023 rad off at q = 1."""
    case = case_from(tmp_path, DEMO, {"design": {"tolerance_mm": 1.0}, "blend": "pcc",
                                      "resample": {"spacing_mm": 1.0, "smoothing_mm": 0.05, "end_straight_mm": 0.0}})
    build_through(case, tmp_path / "build", target="kinematics")
    for q, angle, distance in link_errors(read(tmp_path / "build", "kinematics.json")):
        assert angle <= JOINT_TOL_RAD and distance <= JOINT_TOL_MM, f"q = {q}: {angle:.3g} rad, {distance:.3g} mm"


def test_a_build_without_blend_pcc_has_no_sections_in_kinematics_json(tmp_path):
    case = case_from(tmp_path, DEMO, {"design": {"tolerance_mm": 1.0}, "links": {"count": 2},
                                      "resample": {"spacing_mm": 1.0, "smoothing_mm": 0.05, "end_straight_mm": 0.0}})
    build_through(case, tmp_path / "build", target="kinematics")
    kinematics = read(tmp_path / "build", "kinematics.json")
    assert "pcc_convention" not in kinematics and all("pcc_sections" not in p for p in kinematics["poses"])
    assert all("dh" in link for link in read(tmp_path / "build", "design/summary.json")["links"])
