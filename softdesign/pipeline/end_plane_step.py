"""The end-plane check made at ingest: how far a tilted flat cap's or opening's rim lies past the body's square end.

:func:`softdesign.geometry.end_planes.end_planes` finds each end's plane on
the final surface; the path's ends and end tangents are those of the smooth
curve the build makes from the (regularized) path, as the blend stage makes
it, so the tilt is measured against the body's own square end.  Nothing is
measured without a surface or without inscribed radii.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curves import smooth_curve_from_polyline
from softdesign.geometry.edges import EdgeTable
from softdesign.geometry.end_planes import end_planes
from softdesign.geometry.inlet import end_radii
from softdesign.geometry.network import SelectedPath
from softdesign.limits import MAX_CURVE_SAMPLES
from softdesign.pipeline.backbone_step import curve_options
from softdesign.types import FloatArray

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case


def end_plane_summary(
    case: Case, path: SelectedPath, vertices: FloatArray, faces: np.ndarray, table: EdgeTable | None = None,
    labels: np.ndarray | None = None,
) -> dict[str, dict[str, Any] | None] | None:
    """Per end ("inlet", "outlet"): the plane found there (``EndPlane.as_dict``) or None; None when not measured.

    ``table``: the surface's edge table, and ``labels`` its flat regions, when the caller has them
    (:func:`~softdesign.geometry.end_planes.end_planes`).
    Not measured: no surface, no inscribed radii, a spacing the runner refuses after ingest, or a path the
    blend stage will refuse (it says why).
    """
    if len(faces) == 0 or path.radius is None:
        return None
    if case.resample.count is None and path.length / case.resample.spacing_mm > MAX_CURVE_SAMPLES:
        return None
    try:
        curve = smooth_curve_from_polyline(path.points, curve_options(case))
    except (ConfigError, GeometryError):
        return None
    l = np.array([0.0, 1.0])
    inscribed = np.array(end_radii(path.points, path.radius))
    inlet, outlet = end_planes(vertices, faces, curve.points(l), curve.tangents(l), inscribed, table, labels)
    return {"inlet": None if inlet is None else inlet.as_dict(), "outlet": None if outlet is None else outlet.as_dict()}
