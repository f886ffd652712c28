"""Exact joints through the build (issue 35 item 4): a case of known arcs with ``links.breaks`` at its joints.

The centerline is seed 003's chain of constant-curvature sections written as
VMTK would; the case breaks its links where the sections meet.  The blend
keeps those joints sharp, so ``kinematics.json``'s link transforms at q = 1
are the sections' own (improved D-H, seed 003 eq. 8) within the issue's 1e-4
rad and 1e-4 mm, at the project's default 0.5 mm resampling, interpolated
(``smoothing_mm: 0``) and at the default smoothing (each piece between joints
smoothed on its own, pinned at its joints).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from softdesign.centerline.extract import Centerlines
from softdesign.geometry.se3 import rotvec_from_rotation
from softdesign.io.centerline_vtp import write_centerlines_vtp
from softdesign.pipeline.api import build_through
from softdesign.pipeline.layout import KINEMATICS
from softdesign.pipeline.stages.blend import describe_blend
from tests.helpers.seed_transforms import seed_chain

#: (kappa 1/mm, phi rad, L mm); joints at 20, 32.5 and 47.5 mm of 70: samples of a 0.5 mm grid.
ARCS = ((0.05, 0.4, 20.0), (0.0, 0.0, 12.5), (0.07, 2.0, 15.0), (0.03, -1.5, 22.5))
SPACING_MM = 0.5
ANGLE_TOL = 1e-4  # rad, the issue's
MM_TOL = 1e-4


def section(kappa: float, phi: float, length: float) -> np.ndarray:
    return seed_chain(kappa, phi, length)


@pytest.mark.slow
@pytest.mark.parametrize("smoothing", [{"smoothing_mm": 0.0}, {}], ids=["interpolated", "default-smoothing"])
def test_link_transforms_of_a_case_broken_at_its_joints_are_the_sections(tmp_path, smoothing):
    pose, points = np.eye(4), []
    for kappa, phi, length in ARCS:
        points += [(pose @ section(kappa, phi, s))[:3, 3] for s in np.arange(0.0, length - 1e-9, SPACING_MM)]
        pose = pose @ section(kappa, phi, length)
    points = np.array([*points, pose[:3, 3]])
    write_centerlines_vtp(tmp_path / "arcs.vtp", Centerlines((points,), (np.full(len(points), 2.0),), "given",
                                                             points[0], (points[-1],), 0))
    total = sum(length for _, _, length in ARCS)
    breaks = [0.0, *(float(b) for b in np.cumsum([a[2] for a in ARCS])[:-1] / total), 1.0]
    case = {"name": "arcs", "units": "mm", "final": {"centerline": "arcs.vtp"},
            "resample": {"spacing_mm": SPACING_MM, "end_straight_mm": 0.0, **smoothing},
            "links": {"breaks": breaks}, "export": {"q": [0, 1]}}
    (tmp_path / "arcs.yaml").write_text(yaml.safe_dump(case), encoding="utf-8")
    outcome = build_through(tmp_path / "arcs.yaml", tmp_path / "build", target="kinematics")
    assert outcome.results["blend"].joints == (40, 65, 95)
    assert "sharp joints (link breaks at a corner of the path, not smoothed over) at l = 0.2857, 0.4643, 0.6786" in (
        describe_blend(outcome.results["blend"]))
    document = json.loads((tmp_path / "build" / KINEMATICS).read_text(encoding="utf-8"))
    final = next(p for p in document["poses"] if p["q"] == [1.0] * len(ARCS))
    for link, (kappa, phi, length) in zip(final["links"], ARCS, strict=True):
        got, expected = np.array(link["transform"]), section(kappa, phi, length)
        # the first frame's normal is the build's own (the world axis least along the base tangent): compare the
        # bending angle (frame-free) and the chord length, then the whole transform up to that roll
        assert abs(np.linalg.norm(rotvec_from_rotation(got[:3, :3])) - kappa * length) <= ANGLE_TOL
        assert abs(np.linalg.norm(got[:3, 3]) - np.linalg.norm(expected[:3, 3])) <= MM_TOL
        assert abs(link["length"] - length) <= MM_TOL
    # the chain's end frame from its base, composed from the links: the same bend and reach as the sections'
    tip = np.linalg.multi_dot([np.array(link["transform"]) for link in final["links"]])
    expected_tip = np.linalg.multi_dot([section(*arc) for arc in ARCS])
    bend = np.linalg.norm(rotvec_from_rotation(tip[:3, :3]))
    assert abs(bend - np.linalg.norm(rotvec_from_rotation(expected_tip[:3, :3]))) <= ANGLE_TOL
    assert abs(np.linalg.norm(tip[:3, 3]) - np.linalg.norm(expected_tip[:3, 3])) <= MM_TOL
    # the joints are kept with the blend's samples: the kinematics re-run on the loaded blend are the same bits
    case["export"]["q"] = [0, 0.5, 1]
    (tmp_path / "arcs.yaml").write_text(yaml.safe_dump(case), encoding="utf-8")
    again = build_through(tmp_path / "arcs.yaml", tmp_path / "build", target="kinematics")
    assert {run.name: run.status for run in again.runs}["blend"] == "skipped"
    reloaded = json.loads((tmp_path / "build" / KINEMATICS).read_text(encoding="utf-8"))
    assert next(p for p in reloaded["poses"] if p["q"] == [1.0] * len(ARCS)) == final
