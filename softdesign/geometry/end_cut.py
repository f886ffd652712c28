"""Which plane ends the body at each end: square to the end tangent, or the vessel's detected cap plane.

:mod:`softdesign.geometry.end_planes` finds each end's flat cap or open
boundary loop on the final surface and its tilt theta to the centerline's end
tangent.  A body cut square to that tangent misses a wedge of the vessel up
to ``r tan(theta)`` long on one side and overhangs it as far on the other.
Here each end's cut plane is chosen and expressed in the end frame of the
final shape (columns N, B, T at l = 0 or 1, q = 1), so that the body, whose
end frame moves with q, carries the plane rigidly: at q = 1 the plane has
the detected cap's normal, at any other q it is the same plane in that q's
end frame.

The detected plane may cross the end's axis ``axis_offset_mm`` past (or
short of) the centerline's end (a VMTK centerline starts about a radius
inside an opening).  Not in the papers (the seeds' body ends in the end
frames' normal planes).

Modes (``fit.end_cut``)
    ``auto``       the detected plane's normal through the centerline's end
                   point (the body keeps its length along the axis; the axis
                   offset is recorded, not applied), where a plane is found,
                   its tilt is at most ``MAX_CUT_TILT_DEG`` and its rim gap at
                   least ``MIN_CUT_GAP_MM``; square otherwise, saying why.  With
                   ``export.mould`` each cut is turned into the mould's parting
                   plane (a lean out of it would lock one half), or kept square
                   on a curved q = 0 body.
    ``cap_plane``  the detected plane itself, axis offset included (the body
                   is lengthened or shortened along its axis to reach it),
                   wherever one is found; a tilt above ``MAX_CUT_TILT_DEG``
                   is refused.
    ``normal``     square to the end tangent at both ends (the seeds' body).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.types import FloatArray

#: The largest tilt of a cut plane to the end tangent, degrees: the body is extended or shortened along each
#: generator by up to r tan(30 deg) = 0.58 r, which its end region takes without crowding its rings.
MAX_CUT_TILT_DEG = 30.0
#: A rim gap below this is left square, mm: the detection's own scatter (a 64-gon's sagitta on a 3 mm
#: radius is 0.004 mm; float32 STL caps tilt by hundredths of a degree) and well under a fit's RMS.
MIN_CUT_GAP_MM = 0.05
#: The body's end zone, whose rings slide along the wall to meet the plane, is this many times the largest
#: shift long (each ring step scales by at most 1 +- 1/3) ...
ZONE_FACTOR = 3.0
#: ... and at most this fraction of the body's length (the two ends' zones never meet).
MAX_ZONE_FRACTION = 0.25
#: The ends in path order.
ENDS = ("inlet", "outlet")


def end_normal_local(normal: FloatArray, frame: FloatArray) -> FloatArray:
    """A world direction (3,) in the end frame's coordinates (N, B, T components), (3,) unit."""
    local = np.asarray(frame, float).T @ np.asarray(normal, float)
    return local / np.linalg.norm(local)


def choose_end_cuts(
    mode: str, planes: dict[str, dict[str, Any] | None] | None, frames: FloatArray, length_mm: float,
    mould: bool = False, parting_local: FloatArray | None = None,
) -> dict[str, dict[str, Any]]:
    """Per end ("inlet", "outlet"): whether the body is cut at the detected plane, why, and the plane.

    Parameters
    ----------
    mode : "auto", "cap_plane" or "normal" (see the module notes)
    planes : the ingest's ``end_planes`` (:meth:`EndPlane.as_dict` per end, None where none was found),
        or None when nothing was measured
    frames : (2, 3, 3) end frames (columns N, B, T) of the final shape at l = 0 and l = 1
    length_mm : the final path's length, mm: auto keeps an end square whose plane lies farther from it
        (rim gap plus applied offset) than a zone of ``MAX_ZONE_FRACTION`` of it can take
    mould : the case asks for a two-part casting mould.  A cut leaning out of the mould's parting plane is an
        undercut for one half (a rigid half cannot be drawn off along the plane's normal), so auto turns each
        cut normal into the parting plane (drops its component along the plane's normal, recorded as
        ``parting_lean_deg``); without ``parting_local`` (a curved q = 0 body) the ends stay square.  The case
        file refuses ``cap_plane`` with a mould.
    parting_local : (2, 3) the parting plane's unit normal in each end frame's (N, B, T) coordinates at q = 0
        (:func:`~softdesign.meshing.mould.frame.parting_frame` of a straight q = 0 body), or None

    Returns
    -------
    dict
        Per end: ``applied`` (bool), ``reason``, and the detected ``tilt_deg``, ``rim_gap_mm`` and
        ``axis_offset_mm`` when a plane was found; when applied, ``normal_local`` (3,): the outward unit
        normal of the cut plane in the end frame's (N, B, T) coordinates, and ``offset_mm``: where it crosses
        the axis, mm along the outward tangent from the centerline's end (0 for auto).

    Raises
    ------
    ConfigError
        ``cap_plane`` with a plane tilted more than ``MAX_CUT_TILT_DEG``.
    """
    out: dict[str, dict[str, Any]] = {}
    for k, end in enumerate(ENDS):
        plane = None if planes is None else planes.get(end)
        out[end] = _choose(mode, end, plane, np.asarray(frames[k], float), length_mm)
        if mould and out[end]["applied"]:
            out[end] = _into_parting_plane(out[end], None if parting_local is None else parting_local[k])
    return out


def _into_parting_plane(record: dict[str, Any], parting: FloatArray | None) -> dict[str, Any]:
    """An applied cut turned into the mould's parting plane (normal ``parting``, end-frame coordinates), or
    left square when there is none (a curved q = 0 body)."""
    if parting is None:
        kept = {key: value for key, value in record.items() if key not in ("normal_local", "offset_mm")}
        return {**kept, "applied": False,
                "reason": "export.mould on a curved q = 0 body casts square ends only: square end kept so the mould "
                          "casts the exported body"}
    z = np.asarray(parting, float) / np.linalg.norm(parting)
    normal = np.asarray(record["normal_local"], float)
    along = float(normal @ z)
    turned = normal - along * z
    turned /= np.linalg.norm(turned)
    lean = float(np.degrees(np.arcsin(min(1.0, abs(along)))))
    return {**record, "normal_local": [float(x) for x in turned], "parting_lean_deg": lean,
            "reason": f"{record['reason']}; turned into the mould's parting plane (its {lean:.2f} deg lean out of "
                      "it dropped: a two-part mould cannot release a cap leaning out of its parting plane)"}


def _choose(mode: str, end: str, plane: dict[str, Any] | None, frame: FloatArray, length_mm: float) -> dict[str, Any]:
    if mode == "normal":
        record: dict[str, Any] = {"applied": False, "reason": "fit.end_cut: normal"}
        return record if plane is None else {**record, **_figures(plane)}
    if plane is None:
        return {"applied": False, "reason": "no flat cap or open boundary loop found at this end (or not measured)"}
    figures = _figures(plane)
    if plane["tilt_deg"] > MAX_CUT_TILT_DEG:
        if mode == "cap_plane":
            raise ConfigError(
                f"fit.end_cut: cap_plane: the {end}'s {plane['kind'].replace('_', ' ')} is tilted "
                f"{plane['tilt_deg']:.1f} deg to the centerline's end tangent, more than the {MAX_CUT_TILT_DEG:g} deg "
                "a cut plane may lean; use fit.end_cut: auto or normal (square end), or clip that end of the surface "
                "closer to square (e.g. vmtksurfaceclipper) and re-cap it"
            )
        return {"applied": False, "reason": f"tilt above {MAX_CUT_TILT_DEG:g} deg: square end kept", **figures}
    if mode == "auto" and plane["rim_gap_mm"] < MIN_CUT_GAP_MM:
        return {"applied": False, "reason": f"rim gap below {MIN_CUT_GAP_MM:g} mm: square end kept", **figures}
    if mode == "auto" and ZONE_FACTOR * plane["rim_gap_mm"] > MAX_ZONE_FRACTION * length_mm:
        return {"applied": False, "reason": f"rim gap too long for a {length_mm:.1f} mm path: square end kept",
                **figures}
    local = end_normal_local(np.asarray(plane["normal"], float), frame)  # already outward at both ends
    kind = plane["kind"].replace("_", " ")
    reason = f"{kind} plane detected" + (", axis offset applied" if mode == "cap_plane" else
                                         ", through the centerline's end (axis offset not applied)")
    return {"applied": True, "reason": reason, **figures, "normal_local": [float(x) for x in local],
            "offset_mm": figures["axis_offset_mm"] if mode == "cap_plane" else 0.0}


def _figures(plane: dict[str, Any]) -> dict[str, Any]:
    figures: dict[str, Any] = {key: float(plane[key]) for key in ("tilt_deg", "rim_gap_mm", "radius_mm",
                                                                   "axis_offset_mm")}
    return {"kind": plane["kind"], **figures}
