"""The inward offset a vessel can take, checked once ingest has measured it and before the fit.

``export.offset_mm`` moves the body's skin along its normal, and a hollow
body's chamber lies ``export.wall_mm`` further in.  Before the fit the
body's radius is known as the centerline's inscribed radius
(``MaximumInscribedSphereRadius``: no wall point is nearer the centerline,
so the fitted radius is at least about that).  Where the inscribed radius
plus the offset is not positive, the skin would pass through the centerline
(and a tessellation would turn the section inside out, a mesh that looks
valid); where it less the wall is not positive, the chamber would vanish.
Both are refused with the place and the largest inward offset allowed,
before any fitting is done.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from softdesign.errors import ConfigError

if TYPE_CHECKING:  # only annotations: no import of the case models or the stages here
    from softdesign.config import Case
    from softdesign.pipeline.stages.ingest import IngestResult


def check_offset(case: Case, ingest: IngestResult) -> None:
    """Refuse an inward offset (and wall) at least as large as the vessel's radius anywhere (ConfigError).

    Parameters
    ----------
    case : the validated case (``export.offset_mm``, ``export.wall_mm``, mm)
    ingest : the measured final path; without inscribed radii there is nothing to check before the fit
    """
    radius = ingest.path.radius
    wall = case.export.wall_mm or 0.0
    if radius is None or len(radius) == 0 or min(-case.export.offset_mm, wall - case.export.offset_mm) < 0.0:
        return
    i = int(np.argmin(radius))
    smallest = float(radius[i])
    inward = wall - case.export.offset_mm
    if smallest + case.export.offset_mm > 0.0 and smallest > inward:
        return
    points = ingest.path.points
    along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    place = (f"at l = {along[i] / along[-1]:.4f} ({along[i]:.1f} mm from the inlet, point "
             f"{np.round(points[i], 2).tolist()}), where the vessel's inscribed radius is {smallest:.3f} mm")
    offset = case.export.offset_mm
    if smallest + offset <= 0.0:
        raise ConfigError(
            f"export.offset_mm: {offset:g} mm makes the body's radius {smallest + offset:.3f} mm {place} (its "
            f"smallest); expected offset_mm > {-smallest:.3f} mm, the largest inward offset this vessel allows: "
            "make offset_mm closer to 0 (less negative)"
        )
    raise ConfigError(
        f"export.wall_mm: {wall:g} mm inside export.offset_mm {offset:g} mm leaves the chamber a radius "
        f"of {smallest - inward:.3f} mm {place} (its smallest); expected wall_mm - offset_mm < {smallest:.3f} mm: "
        f"a thinner wall or an offset closer to 0 (offset_mm > {wall - smallest:.3f} mm with this wall)"
    )
