"""Kinematics figures of a regression check: ``kinematics.json`` per q and link, against the reference's.

Link transforms and the chain transforms of a pose (``base_to_tip``,
``base_to_world``) by translation (mm) and rotation angle (rad); link length
and POE theta1 (mm), POE theta2 (rad); the frame convention must match.  A
pose is matched by its q, one value or one per link as the kinematics stage
writes it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softdesign.errors import InputDataError
from softdesign.pipeline.layout import KINEMATICS
from softdesign.regression.figures import CheckOptions, Figure, is_number, missing_figure, read_json, scalar_figure

#: Decimals of q that identify a pose (q values are written as the case file gives them).
Q_DECIMALS = 9
#: Chain-level transforms of a pose, compared like link transforms when either side has them.
POSE_TRANSFORMS = ("base_to_tip", "base_to_world")


def pose_difference(pose: np.ndarray, ref_pose: np.ndarray) -> tuple[float, float]:
    """Translation difference (mm) and angle of ``R_ref^T R`` (rad, in [0, pi]) of two (4, 4) poses."""
    translation = float(np.linalg.norm(pose[:3, 3] - ref_pose[:3, 3]))
    relative = ref_pose[:3, :3].T @ pose[:3, :3]
    skew = relative - relative.T
    skew = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    # atan2 keeps the angle accurate near 0, where acos((trace - 1) / 2) loses half the digits.
    angle = float(np.arctan2(0.5 * np.linalg.norm(skew), 0.5 * (np.trace(relative) - 1.0)))
    return translation, angle


def compare_kinematics_files(
    build_dir: Path, reference_dir: Path, options: CheckOptions, notes: list[str]
) -> list[Figure]:
    """Figures of ``kinematics.json`` in two build folders; a note (no figures) when neither has one."""
    ours, theirs = build_dir / KINEMATICS, reference_dir / KINEMATICS
    if not ours.is_file() and not theirs.is_file():
        notes.append(f"no {KINEMATICS} on either side: kinematics not compared")
        return []
    if not ours.is_file() or not theirs.is_file():
        return [missing_figure("kinematics", KINEMATICS, in_build=ours.is_file())]
    return compare_kinematics(read_json(ours), read_json(theirs), options, ours.as_posix(), theirs.as_posix())


def compare_kinematics(
    build: dict, ref: dict, options: CheckOptions, where: str = KINEMATICS, ref_where: str | None = None
) -> list[Figure]:
    """Figures of two ``kinematics.json`` objects: frames, then per q each link and the chain transforms."""
    frames_ok = build.get("frames") == ref.get("frames")
    figures = [Figure("kinematics", "frames", None, None, frames_ok, build.get("frames"), ref.get("frames"))]
    ref_where = ref_where or "reference " + where
    ours, theirs = _keyed(build, "poses", "q", where), _keyed(ref, "poses", "q", ref_where)
    for q in sorted(set(ours) | set(theirs), key=_numeric_order):
        item = f"kinematics q={q}"
        if q not in ours or q not in theirs:
            figures.append(missing_figure(item, "pose", in_build=q in ours))
            continue
        pose_wheres = (f"{where}: pose q={q}", f"{ref_where}: pose q={q}")
        figures += _pose_figures(item, ours[q], theirs[q], options, pose_wheres)
    return figures


def _pose_figures(
    item: str, pose: dict, ref_pose: dict, options: CheckOptions, wheres: tuple[str, str]
) -> list[Figure]:
    """``wheres``: where the build's and the reference's pose are, for messages."""
    where, ref_where = wheres
    ours, theirs = _keyed(pose, "links", "index", where), _keyed(ref_pose, "links", "index", ref_where)
    figures: list[Figure] = []
    for index in sorted(set(ours) | set(theirs), key=_numeric_order):
        link_item = f"{item} link {index}"
        if index not in ours or index not in theirs:
            figures.append(missing_figure(link_item, "link", in_build=index in ours))
            continue
        link_wheres = (f"{where} link {index}", f"{ref_where} link {index}")
        figures += _link_figures(link_item, ours[index], theirs[index], options, link_wheres)
    for key in POSE_TRANSFORMS:
        if pose.get(key) is not None or ref_pose.get(key) is not None:
            key_wheres = (f"{where} {key}", f"{ref_where} {key}")
            figures += _transform_figures(f"{item} {key}", pose.get(key), ref_pose.get(key), options, key_wheres)
    return figures


def _link_figures(
    item: str, link: dict, ref_link: dict, options: CheckOptions, wheres: tuple[str, str]
) -> list[Figure]:
    figures = _transform_figures(item, link.get("transform"), ref_link.get("transform"), options, wheres)
    poe, ref_poe = link.get("poe") or {}, ref_link.get("poe") or {}
    for figure, value, reference, tolerance in (
        ("length_mm", link.get("length"), ref_link.get("length"), options.distance_mm),
        ("poe_theta1_mm", poe.get("theta1"), ref_poe.get("theta1"), options.distance_mm),
        ("poe_theta2_rad", poe.get("theta2"), ref_poe.get("theta2"), options.rotation_rad),
    ):
        figures.append(scalar_figure(item, figure, value, reference, tolerance))
    return figures


def _transform_figures(
    item: str, transform: Any, ref_transform: Any, options: CheckOptions, wheres: tuple[str, str]
) -> list[Figure]:
    if transform is None or ref_transform is None:
        return [missing_figure(item, "transform", in_build=transform is not None)]
    translation, angle = pose_difference(_pose(transform, wheres[0]), _pose(ref_transform, wheres[1]))
    return [
        Figure(item, "translation_mm", translation, options.distance_mm, translation <= options.distance_mm),
        Figure(item, "rotation_rad", angle, options.rotation_rad, angle <= options.rotation_rad),
    ]


def _keyed(parent: dict, field_name: str, key: str, where: str) -> dict[str, dict]:
    """``parent[field_name]`` (a list of objects) keyed by the text of each one's ``key`` (a number or numbers)."""
    entries = parent.get(field_name)
    if not isinstance(entries, list):
        raise InputDataError(f"{where}: '{field_name}' must be a list, got {type(entries).__name__}")
    out: dict[str, dict] = {}
    for i, entry in enumerate(entries):
        value = entry.get(key) if isinstance(entry, dict) else None
        values: list[Any] = value if isinstance(value, list) and value else [value]
        if not all(is_number(v) for v in values):
            raise InputDataError(f"{where}: {field_name}[{i}].{key} must be a number or numbers, got {value!r}")
        # One q per link, all equal, is the same pose as that single q: name it once.
        texts = [f"{round(v, Q_DECIMALS):.12g}" for v in values]
        out[texts[0] if len(set(texts)) == 1 else ",".join(texts)] = entry
    return out


def _numeric_order(key: str) -> list[float]:
    return [float(part) for part in key.split(",")]


def _pose(value: Any, where: str) -> np.ndarray:
    try:
        pose = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):  # ragged or non-numeric lists
        pose = np.zeros(0)
    if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
        raise InputDataError(f"{where}: expected a finite 4x4 transform, got {str(value)[:80]}")
    return pose
