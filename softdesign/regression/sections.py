"""The manifest's stage sections compared by a table: one row per section, its figures and their named tolerances.

A :class:`Section` names the check's item, the block under ``metrics`` it
reads and its figures, each a pointer into the block (``/`` between keys,
``*`` for every key or index either side has) with the name of its
tolerance (:data:`TOLERANCES`).  Adding a stage to ``softdesign check`` is one
row of :data:`SECTIONS`.

Either side may lack a block: a reference built before the stage existed
gives a note (it cannot judge), a build without a block the reference has
fails, and a block whose flag (:attr:`Section.asked`) is false on both sides
(a mould, volume mesh or design the case did not ask for) is not compared.
A figure the reference has and the build lacks, or the other way round, fails.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

from softdesign.regression.feasibility import RHO_KAPPA_TOL, STRETCH_TOL
from softdesign.regression.figures import (
    RESIDUAL_FLOOR_DEG,
    RESIDUAL_FLOOR_MM,
    CheckOptions,
    Figure,
    is_number,
    missing_figure,
    residual_tolerance,
    scalar_figure,
)

#: The named tolerances a figure may use: absolute (mm, rad, or the dimensionless ones) or relative.
#: ``exact``: the same value (counts, flags, verdicts); ``rtol``: within ``CheckOptions.rtol`` of the reference;
#: ``residual_mm``, ``residual_deg``: a residual (how far a designed or fitted thing is from its target), within the
#: smaller of ``distance_mm`` (``rotation_rad`` in degrees) and ``rtol`` of the reference plus a floor
#: (:func:`~softdesign.regression.figures.residual_tolerance`): residuals are often far below the absolute
#: tolerance, where it alone would let a change of a percent of them pass unseen.
TOLERANCES = ("distance_mm", "rotation_rad", "rtol", "stretch", "rho_kappa", "exact", "residual_mm", "residual_deg")


@dataclass(frozen=True)
class Section:
    """One row of the table: the check's item, the metrics block and its figures (pointer, tolerance name).

    ``asked`` names the block's flag that says whether the case asked for the stage: false on both sides, the
    section is not compared.
    """

    item: str
    block: str
    figures: tuple[tuple[str, str], ...]
    asked: str = "requested"


#: Every manifest section compared by the table (meshes, kinematics.json, fit and feasibility have their own code).
SECTIONS: tuple[Section, ...] = (
    # breaks from links.length_mm divide by the path's length: within rtol, not to the bit
    Section("links", "links", (("count", "exact"), ("breaks/*", "rtol"))),
    Section("blend", "blend", (
        ("final_path/length_mm", "distance_mm"), ("final_path/samples", "exact"),
        ("final_path/max_curvature_per_mm", "rtol"), ("initial_length_mm", "distance_mm"),
        ("shortening/min_length_mm", "distance_mm"), ("mode", "exact"),
    )),
    # the kinematics stage's arc check: how far each link's q = 1 centerline is from one constant-curvature arc
    Section("kinematics", "kinematics", (("links", "exact"), ("arc_check/max_deviation_mm/*", "residual_mm"))),
    # the design stage's composed chain: its sections, joints (normalized l, as the links' breaks) and residuals
    Section("design", "design", (
        ("designed", "exact"), ("links", "exact"), ("meets_tolerance", "exact"), ("breaks/*", "rtol"),
        ("chain_max_deviation_mm", "residual_mm"), ("tip_error_mm", "residual_mm"), ("tip_error_deg", "residual_deg"),
    ), asked="designed"),
    Section("mould", "mould", (
        ("requested", "exact"), ("parts/*/volume_mm3", "rtol"), ("parts/*/ok", "exact"), ("parts/*/bodies", "exact"),
        ("cavity/cavity_mm3", "rtol"), ("cavity/cast_mm3", "rtol"), ("cavity/ok", "exact"), ("disjoint/ok", "exact"),
        ("pull/*/ok", "exact"), ("core", "exact"),
    )),
    Section("volume_mesh", "volume_mesh", (
        ("requested", "exact"), ("per_q/*/q", "exact"), ("per_q/*/body_volume_mm3", "rtol"),
        ("per_q/*/volume_mm3", "rtol"), ("per_q/*/boundary_watertight", "exact"), ("per_q/*/boundary_shells", "exact"),
    )),
)

if any(tolerance not in TOLERANCES for section in SECTIONS for _, tolerance in section.figures):
    raise RuntimeError("softdesign.regression.sections: a figure names a tolerance not in TOLERANCES")


def compare_sections(
    build: dict, reference: dict, options: CheckOptions, notes: list[str], sections: tuple[Section, ...] = SECTIONS
) -> list[Figure]:
    """Figures of every section of the table, in its order."""
    figures: list[Figure] = []
    for section in sections:
        figures += compare_section(section, build, reference, options, notes)
    return figures


def compare_section(section: Section, build: dict, reference: dict, options: CheckOptions,
                    notes: list[str]) -> list[Figure]:
    """Figures of one section: each pointer expanded over both sides, each value within its tolerance."""
    ours, theirs = _block(build, section.block), _block(reference, section.block)
    if theirs is None:
        if ours is not None:
            notes.append(f"the reference has no metrics.{section.block} (built before it existed): {section.item} "
                         "not compared")
        return []
    if ours is None:
        return [missing_figure(section.item, f"metrics.{section.block}", in_build=False)]
    if ours.get(section.asked) is False and theirs.get(section.asked) is False:
        notes.append(f"{section.item}: not asked for on either side: not compared")
        return []
    figures = []
    for pointer, tolerance in section.figures:
        for name, value, ref in _expand(pointer.split("/"), ours, theirs, ""):
            figures.append(_figure(section.item, name, value, ref, tolerance, options))
    return figures


_ABSENT = object()


def _block(manifest: dict, key: str) -> dict | None:
    metrics = manifest.get("metrics")
    block = metrics.get(key) if isinstance(metrics, dict) else None
    return block if isinstance(block, dict) else None


def _expand(parts: list[str], ours: Any, theirs: Any, prefix: str) -> Iterator[tuple[str, Any, Any]]:
    """(figure name, build value, reference value) of every path matching ``parts``; _ABSENT where a side has none."""
    if not parts:
        yield prefix, ours, theirs
        return
    head, rest = parts[0], parts[1:]
    keys = _keys(ours, theirs) if head == "*" else [head]
    for key in keys:
        name = f"{prefix}/{key}" if prefix else str(key)
        yield from _expand(rest, _child(ours, key), _child(theirs, key), name)


def _keys(ours: Any, theirs: Any) -> list[Any]:
    """Every key (dicts, in order of appearance) or index (lists) either side has."""
    if isinstance(ours, list) or isinstance(theirs, list):
        return list(range(max(len(x) if isinstance(x, list) else 0 for x in (ours, theirs))))
    keys: list[Any] = []
    for side in (theirs, ours):
        if isinstance(side, dict):
            keys += [k for k in side if k not in keys]
    return keys


def _child(node: Any, key: Any) -> Any:
    if isinstance(node, dict):
        return node.get(key, _ABSENT)
    if isinstance(node, list) and isinstance(key, int) and key < len(node):
        return node[key]
    if isinstance(node, list) and isinstance(key, str) and key.isdigit() and int(key) < len(node):
        return node[int(key)]
    return _ABSENT


def _figure(item: str, name: str, value: Any, ref: Any, tolerance: str, options: CheckOptions) -> Figure:
    """One figure within the named tolerance; a value on one side only fails."""
    if value is _ABSENT or ref is _ABSENT:
        if value is _ABSENT and ref is _ABSENT:
            return Figure(item, name, None, None, True, note="absent on both sides")
        return missing_figure(item, name, in_build=value is not _ABSENT)
    if tolerance == "exact" or not (is_number(value) and is_number(ref)):
        same = value == ref
        return Figure(item, name, None, None, same, _text(value), _text(ref), "" if same else "expected the same")
    if tolerance == "rtol":
        allowed = options.rtol * abs(float(ref))
        return replace(scalar_figure(item, name, value, ref, allowed), note=f"rtol {options.rtol:g}")
    if tolerance in ("residual_mm", "residual_deg"):
        return _residual_figure(item, name, value, ref, tolerance, options)
    absolute = {"distance_mm": options.distance_mm, "rotation_rad": options.rotation_rad, "stretch": STRETCH_TOL,
                "rho_kappa": RHO_KAPPA_TOL}[tolerance]
    return scalar_figure(item, name, value, ref, absolute)


def _residual_figure(item: str, name: str, value: Any, ref: Any, tolerance: str, options: CheckOptions) -> Figure:
    """A residual within the smaller of the absolute tolerance (mm, or degrees) and rtol of the reference + floor."""
    absolute, floor, unit = ((options.distance_mm, RESIDUAL_FLOOR_MM, "mm") if tolerance == "residual_mm" else
                             (math.degrees(options.rotation_rad), RESIDUAL_FLOOR_DEG, "deg"))
    allowed = residual_tolerance(ref, absolute, options.rtol, floor)
    note = f"the smaller of {absolute:g} {unit} and rtol {options.rtol:g} of the reference + {floor:g} {unit}"
    return replace(scalar_figure(item, name, value, ref, allowed), note=note)


def _text(value: Any) -> Any:
    """A value as a figure shows it: numbers, flags and text as they are, anything else as its text."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return str(value)
