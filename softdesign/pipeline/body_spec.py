"""The case's export keys as the solid's specification: the one conversion every stage that makes the body uses.

Export, actuation, mould, volume mesh, feasibility and ``simulate`` all build the same body; each takes its
:class:`~softdesign.meshing.volume.BodySpec` from here, so no stage imports another for it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from softdesign.meshing.end_cut import end_cuts_from_record
from softdesign.meshing.volume import BodySpec

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.pipeline.stages.fit import FitResult


def body_spec(case: Case, fit: FitResult | None = None) -> BodySpec:
    """The case's export keys as a solid specification, with the fit's end cuts when ``fit`` is given."""
    e = case.export
    spec = BodySpec(offset_mm=e.offset_mm, wall_mm=e.wall_mm or 0.0, port_mm=e.port_mm or 0.0)
    return spec if fit is None else replace(spec, end_cuts=end_cuts_from_record(fit.summary.get("end_cut")))
