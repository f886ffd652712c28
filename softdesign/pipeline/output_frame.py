"""Where the output files' coordinates are: the patient's (scanner) frame, or the device's base frame.

``export.frame: patient`` (the default) writes every mesh in the input files'
coordinates, so it overlays the vessel.  ``export.frame: base`` writes the
meshes, the exported centerlines (with their frames), the mould's parts and
the volume meshes in the q = 0 body's base frame: its base point at the
origin, z along the axis (the frame's T), x along N, as printing and CAD
expect.  The move is rigid, so every figure (volumes, areas, walls, checks)
is the same; the manifest records it (``metrics.export.frame``) both ways.
Kinematics, the design and the report stay in the patient's frame, where the
vessel is.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.types import FloatArray


def output_pose(frame: str, base2patient: FloatArray) -> FloatArray | None:
    """``patient2output`` (4, 4) for ``export.frame``, or None for ``patient`` (no move).

    Parameters
    ----------
    frame : "patient" or "base"
    base2patient : (4, 4), the q = 0 body's frame at l = 0 ([N B T c]), mm
    """
    return None if frame == "patient" else _inverse(np.asarray(base2patient, float))


def base_pose(shape: Any) -> FloatArray:
    """``base2patient`` (4, 4): the blended shape's frame at q = 0, l = 0."""
    return np.asarray(shape.curve_at(0.0).poses([0.0])[0], float)


def _inverse(pose: FloatArray) -> FloatArray:
    inverse = np.eye(4)
    inverse[:3, :3] = pose[:3, :3].T
    inverse[:3, 3] = -pose[:3, :3].T @ pose[:3, 3]
    return inverse


def moved_points(points: FloatArray, patient2output: FloatArray | None) -> FloatArray:
    """Points (..., 3) mm in the output frame (unchanged, the same array, without a move)."""
    if patient2output is None:
        return points
    return np.asarray(points, float) @ patient2output[:3, :3].T + patient2output[:3, 3]


def moved_vectors(vectors: FloatArray, patient2output: FloatArray | None) -> FloatArray:
    """Directions (..., 3) in the output frame (rotated only)."""
    if patient2output is None:
        return vectors
    return np.asarray(vectors, float) @ patient2output[:3, :3].T


def frame_record(frame: str, patient2output: FloatArray | None) -> dict[str, Any]:
    """The manifest's record: the frame's name and both poses (4 x 4 row lists, mm)."""
    pose = np.eye(4) if patient2output is None else patient2output
    back = _inverse(pose)
    return {"name": frame, "output_from_patient": pose.tolist(), "patient_from_output": back.tolist(),
            "meaning": "output files' coordinates = output_from_patient applied to the input files' (mm)"}
