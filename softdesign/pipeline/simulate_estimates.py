"""The simulate stage's result and what actuation.csv takes from it: three columns of model estimates per row.

Apart from :mod:`softdesign.pipeline.stages.simulate` (which lays the chambers out with the actuation stage's
code) so that the actuation stage can read the result without importing the stage that imports it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from softdesign.io.format_names import q_label

#: actuation.csv's columns for the estimates (only when the build has them); ``fe_``: the rod model's
#: ``pressure_kpa`` is in every row (issue 41), the finite elements' estimates keep their own columns.
ESTIMATE_COLUMNS = ("fe_pressure_kpa", "fe_pressure_arc_error_mm", "fe_pressure_source")


@dataclass(frozen=True)
class SimulateResult:
    """The figures of every solve (JSON-ready)."""

    summary: dict[str, Any]


def arc_error_mm(figures: dict[str, Any]) -> float:
    """The remaining weighted arc error of a solve (the norm of its error vector), mm."""
    return math.hypot(*figures["target"]["error_mm"])


def estimate_cells(result: SimulateResult | None, q: float, section: int) -> dict[str, Any] | None:
    """actuation.csv's estimate cells of (q, section from 1) as {column: per-chamber list or value}, or None."""
    if result is None:
        return None
    for solve in result.summary["solves"]:
        if solve["section"] == section and q_label(solve["q"]) == q_label(q):
            return {"pressure_kpa": solve["pressures_kpa"], "pressure_arc_error_mm": arc_error_mm(solve),
                    "pressure_source": solve["source"]}
    return None
