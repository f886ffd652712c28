"""The paths of a centerline network in words, for ``init``'s case file and notes and for ``validate``.

One line a path (:func:`path_lines`): its length, its radius at the inlet
and at the end, where it leaves the others (mm from the inlet) and which
opening it ends at, the main vessel marked
(:mod:`softdesign.geometry.path_survey` has the facts and the rule).
Lengths are printed in the files' unit with mm beside them
(:func:`softdesign.pipeline.length_text.length_text`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from softdesign.geometry.path_survey import PathFacts
from softdesign.pipeline.length_text import length_text
from softdesign.types import UNIT_SCALE_TO_MM, FloatArray

#: How the main vessel is marked in the list.
MAIN_MARK = "the main vessel"


def path_line(facts: PathFacts, units: str, to_mm: float, main: int) -> str:
    """One path in words (see the module notes); ``to_mm`` turns the facts' lengths into mm."""
    def length(value: float) -> str:
        return length_text(value * to_mm, units)

    parts = [f"path {facts.index}: {length(facts.length)} long"]
    if facts.radius_inlet is not None and facts.radius_end is not None:
        parts.append(f"radius {length(facts.radius_inlet)} at the inlet, {length(facts.radius_end)} at the end")
    else:
        parts.append("no radius")
    if facts.leaves is not None:
        other, at = facts.leaves
        parts.append(f"leaves path {other} at {length(at)} from the inlet")
    end = _point_text(facts.end * to_mm / UNIT_SCALE_TO_MM[units])
    parts.append(f"ends at opening {facts.opening} [{end}]")
    return ", ".join(parts) + (f" ({MAIN_MARK})" if facts.index == main else "")


def _point_text(point: FloatArray) -> str:
    """'4.997, -0.000, -7.995': four significant figures of the largest coordinate, the others to its decimals."""
    largest = float(np.abs(point).max())
    decimals = max(0, 3 - math.floor(math.log10(largest))) if largest > 0.0 else 3
    return ", ".join(f"{v:.{decimals}f}" for v in point)


def path_lines(facts: Sequence[PathFacts], units: str, to_mm: float, main: int) -> list[str]:
    """Every path in words, in the file's order."""
    return [path_line(f, units, to_mm, main) for f in facts]


def alternatives_line(facts: Sequence[PathFacts], main: int) -> str | None:
    """'the alternatives: path 5 (leaves path 3 at ...), ...' in order of lumen, or None for a single path."""
    others = [f for f in facts if f.index != main]
    if not others:
        return None
    ranked = sorted(others, key=lambda f: -(f.lumen if f.lumen is not None else f.length))
    return "the alternatives, widest longest first: " + ", ".join(f"path {f.index}" for f in ranked)
