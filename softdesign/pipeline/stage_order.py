"""The stages of a build in build order (:data:`STAGES`), and what the runner asks of them as a whole.

Kept out of the :mod:`softdesign.pipeline.stages` package, which imports nothing: importing one stage's module
(the report loads six stages' results) then does not import every stage and what they compute with.
"""

from __future__ import annotations

from pathlib import Path

from softdesign.config import Case
from softdesign.pipeline import inputs
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages import (
    actuation,
    blend,
    design,
    device_fe,
    export,
    fabrication,
    feasibility,
    fit,
    ingest,
    kinematics,
    links,
    mould,
    simulate,
    volume_mesh,
)

#: Every stage, in build order.
STAGES: list[Stage] = [
    ingest.STAGE, design.STAGE, blend.STAGE, links.STAGE, kinematics.STAGE, fit.STAGE, simulate.STAGE,
    actuation.STAGE, device_fe.STAGE, export.STAGE, mould.STAGE, volume_mesh.STAGE, feasibility.STAGE,
    fabrication.STAGE,
]


def stages_through(name: str) -> list[Stage]:
    """The stages up to and including ``name`` (its upstream, in order)."""
    names = [s.name for s in STAGES]
    return STAGES[: names.index(name) + 1]


def input_files(case: Case) -> list[Path]:
    """Files the build reads (ConfigError naming the field when one is missing)."""
    return inputs.input_files(case)
