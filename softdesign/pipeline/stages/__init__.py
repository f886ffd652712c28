"""The stages of a build, in order; each module owns one (its STAGE: run, write, load, describe).

ingest -> blend -> links -> kinematics -> fit -> export (DESIGN.md's five
stages, with the link breaks a product of their own between blend and
kinematics: both kinematics and the fit consume them) -> mould (a casting
mould of the q = 0 body, when the case asks for one) -> volume_mesh (tetrahedra of
the body for simulators, when asked for) -> feasibility (skin
stretch and wall thickness, judged against the case's material).
"""

from __future__ import annotations

from pathlib import Path

from softdesign.config import Case
from softdesign.pipeline import inputs
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages import (
    blend,
    export,
    feasibility,
    fit,
    ingest,
    kinematics,
    links,
    mould,
    volume_mesh,
)

#: Every stage, in build order.
STAGES: list[Stage] = [
    ingest.STAGE, blend.STAGE, links.STAGE, kinematics.STAGE, fit.STAGE, export.STAGE, mould.STAGE, volume_mesh.STAGE,
    feasibility.STAGE,
]


def stages_through(name: str) -> list[Stage]:
    """The stages up to and including ``name`` (its upstream, in order)."""
    names = [s.name for s in STAGES]
    return STAGES[: names.index(name) + 1]


def input_files(case: Case) -> list[Path]:
    """Files the build reads (ConfigError naming the field when one is missing)."""
    return inputs.input_files(case)
