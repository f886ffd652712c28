"""The section curvature's nested-refinement study, shared by its test and by ``make study`` (pipelines/study.py).

A straight three-chamber section (octagonal chambers, 4 mm elements across, 8.5 mm along: 648 tets) is solved
at its coarse mesh and at one and two red refinements (:mod:`softdesign.mechanics.refine`) with 5 kPa in chamber
0.  Levels 0 and 1 take about 15 s; level 2 (61,188 quadratic nodes) about 9 minutes on 2 cores, so the test
reads it from :data:`REFERENCE`, which ``make study`` re-derives (all three levels) and rewrites.  The test solves
levels 0 and 1 afresh and checks them against the recorded ones: a change to the mesher, the refinement or the
solver that moves them makes the recorded level 2 stale, and the test says to run ``make study``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics.newton import NewtonSettings
from softdesign.mechanics.refine import refine_section
from softdesign.mechanics.section import SectionMesh, simulate_section
from tests.helpers.fe_meshes import three_chamber_section

#: Ecoflex-like neo-Hookean: mu 40 kPa, kappa / mu = 1000 (the law of tests/mechanics/test_section.py).
LAW = HyperelasticLaw("neo-hookean", 20.0, 0.0, 0.0, 40_000.0, "test")
#: A 10 mm section 20 mm long, chambers 2 mm across at 2.5 mm, 1.5 mm end walls.
SHAPE = {"radius": 5.0, "distance": 2.5, "chamber_diameter": 2.0, "length": 20.0, "end_wall": 1.5}
#: The study's coarse mesh: octagonal chambers, 4 mm across, 8.5 mm along (648 tets).
FULL_STUDY = {"size": 4.0, "axial_size": 8.5, "ring_turn": 0.25}
#: Small, so one load step each and the curvature well above the solver's tolerance.
STUDY_KPA = 5.0
LEVELS = 3
#: The recorded study (all three levels), written by ``make study``.
REFERENCE = Path(__file__).resolve().parents[1] / "mechanics" / "refinement_reference.json"


def coarse_section() -> SectionMesh:
    """The study's level-0 section."""
    return three_chamber_section(SHAPE["radius"], SHAPE["distance"], SHAPE["chamber_diameter"], SHAPE["length"],
                                 SHAPE["end_wall"], FULL_STUDY["size"], axial_size=FULL_STUDY["axial_size"],
                                 ring_turn=FULL_STUDY["ring_turn"])


def _angle_between(a: float, b: float) -> float:
    return abs(float(np.angle(np.exp(1j * (a - b)))))


def solve_level(coarse: SectionMesh, level: int) -> dict[str, float]:
    """Curvature 1/mm, the bending direction's error from the side opposite chamber 0 (rad) and the quadratic
    node count of ``coarse`` refined ``level`` times, chamber 0 at :data:`STUDY_KPA`."""
    section = coarse if level == 0 else refine_section(coarse, level)
    result = simulate_section(section, LAW, np.array([STUDY_KPA, 0.0, 0.0]), NewtonSettings(load_steps=1))
    return {"level": level, "kappa_per_mm": result.kappa,
            "phi_error_rad": _angle_between(result.phi, coarse.chamber_angles[0] + np.pi),
            "tets": len(section.tets), "linear_nodes": len(section.points)}


def load_reference(path: Path = REFERENCE) -> dict[str, Any]:
    """The recorded study: ``levels`` (one :func:`solve_level` dict each) and how it was made."""
    document: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return document
