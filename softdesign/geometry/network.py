"""Centerline networks as VMTK writes them, and the choice of one path through them.

``vmtkcenterlines`` writes one polyline per outlet, all starting at the inlet
seed and sharing the trunk.  ``vmtkbranchextractor`` splits them into tracts
with cell arrays ``CenterlineIds`` (which outlet's centerline) and
``TractIds`` (order along it); a path is then re-assembled from its tracts.
This module is pure: arrays in, arrays out.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softdesign.errors import InputDataError
from softdesign.geometry.inlet import widest_end_flip
from softdesign.geometry.median import median
from softdesign.geometry.rows import distinct_rows
from softdesign.types import FloatArray, Points

#: VMTK's cell arrays that identify tracts of a branch-split network.
TRACT_KEYS = ("CenterlineIds", "TractIds", "GroupIds", "Blanking")
#: Fewer distinct points than this cannot carry a smooth curve with torsion.
MIN_PATH_POINTS = 4


@dataclass(frozen=True)
class Polyline:
    """One VMTK polyline cell.

    Attributes
    ----------
    points : (n, 3) float, mm
    radius : (n,) float, mm, or None -- ``MaximumInscribedSphereRadius``
    cell_data : VMTK's per-cell integers (``CenterlineIds``, ``TractIds``, ...)
    """

    points: Points
    radius: FloatArray | None = None
    cell_data: dict[str, int] = field(default_factory=dict)


@dataclass(frozen=True)
class CenterlineNetwork:
    """Every polyline of one centerline file, in file order; ``notes``: what reading it did (segments joined)."""

    polylines: tuple[Polyline, ...]
    source: str = "centerline"
    notes: tuple[str, ...] = ()

    @property
    def branch_split(self) -> bool:
        """True for ``vmtkbranchextractor`` output (tracts with CenterlineIds and TractIds)."""
        return bool(self.polylines) and all(
            "CenterlineIds" in p.cell_data and "TractIds" in p.cell_data for p in self.polylines
        )

    def path_ids(self) -> list[int]:
        """Indices a case's ``path:`` may take: polyline indices, or CenterlineIds when split."""
        if self.branch_split:
            return sorted({p.cell_data["CenterlineIds"] for p in self.polylines})
        return list(range(len(self.polylines)))


@dataclass(frozen=True)
class SelectedPath:
    """One path, oriented so that index 0 is the inlet (l = 0).

    Attributes
    ----------
    points : (n, 3) float, mm, consecutive duplicates removed
    radius : (n,) float, mm, or None
    index : the ``path:`` value that chose it
    notes : what was done on the way (duplicates removed, orientation rule)
    """

    points: Points
    radius: FloatArray | None
    index: int
    notes: tuple[str, ...] = ()

    @property
    def length(self) -> float:
        """Polyline length, mm."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())


@dataclass(frozen=True)
class Orientation:
    """How to orient a path: towards an inlet point, or as the network shares it."""

    inlet: FloatArray | None = None
    reverse: bool = False


def select_path(network: CenterlineNetwork, index: int, orientation: Orientation = Orientation()) -> SelectedPath:
    """Assemble, clean and orient path ``index`` of a network.

    Parameters
    ----------
    network : the file's polylines
    index : polyline index, or ``CenterlineIds`` value for a branch-split file
    orientation : inlet point (mm) and/or reverse flag

    Raises
    ------
    InputDataError
        ``index`` is not a path of the network, or the path is degenerate.
    """
    valid = network.path_ids()
    if not valid:
        raise InputDataError(f"{network.source}: the file has no polylines (no lines); expected VMTK centerlines")
    if index not in valid:
        raise InputDataError(
            f"{network.source}: final.path {index} is out of range; this file has paths "
            f"{_ranges(valid)}; set path: to one of them"
        )
    points, radius = assemble_path(network, index)
    points, radius, notes = _drop_consecutive_duplicates(points, radius, f"{network.source}: path {index}")
    _check_points(points, f"{network.source}: path {index}")
    flip, why = _needs_flip(network, index, points, orientation, radius)
    if flip:
        points = points[::-1].copy()
        radius = None if radius is None else radius[::-1].copy()
    return SelectedPath(points, radius, index, tuple(notes) + (why,))


def assemble_path(network: CenterlineNetwork, index: int) -> tuple[Points, FloatArray | None]:
    """Points and radii of path ``index`` in file order (tracts joined in TractIds order)."""
    if not network.branch_split:
        line = network.polylines[index]
        return np.array(line.points, float), _copy_or_none(line.radius)
    tracts = sorted(
        (p for p in network.polylines if p.cell_data["CenterlineIds"] == index),
        key=lambda p: p.cell_data["TractIds"],
    )
    points = np.concatenate([t.points for t in tracts])
    if all(t.radius is not None for t in tracts):
        return points, np.concatenate([t.radius for t in tracts])
    return points, None


def all_paths(network: CenterlineNetwork, orientation: Orientation = Orientation()) -> list[SelectedPath]:
    """Every path of the network, each oriented inlet first (for branch tests)."""
    return [select_path(network, i, orientation) for i in network.path_ids()]


def _copy_or_none(values: FloatArray | None) -> FloatArray | None:
    return None if values is None else np.array(values, float)


def _drop_consecutive_duplicates(
    points: Points, radius: FloatArray | None, where: str
) -> tuple[Points, FloatArray | None, list[str]]:
    if len(points) < 2:
        return points, radius, []
    step = np.linalg.norm(np.diff(points, axis=0), axis=1)
    scale = max(float(np.ptp(points, axis=0).max()), 1.0)
    dup = np.flatnonzero(step <= 1e-9 * scale) + 1
    if dup.size == 0:
        return points, radius, []
    keep = np.ones(len(points), bool)
    keep[dup] = False
    note = f"{where}: removed {dup.size} consecutive duplicate point(s) at file position(s) {dup.tolist()[:10]}"
    return points[keep], None if radius is None else radius[keep], [note]


def _check_points(points: Points, where: str) -> None:
    if not np.all(np.isfinite(points)):
        bad = np.flatnonzero(~np.all(np.isfinite(points), axis=1))
        raise InputDataError(
            f"{where}: {bad.size} point(s) have NaN or infinite coordinates (first at position {bad[0]}); "
            "re-export the centerline"
        )
    distinct = len(distinct_rows(points).rows)
    if distinct < MIN_PATH_POINTS:
        raise InputDataError(
            f"{where}: expected at least {MIN_PATH_POINTS} distinct points, got {distinct}; "
            "the centerline is too short or collapsed - re-run vmtkcenterlines or pick another path"
        )


def _needs_flip(
    network: CenterlineNetwork, index: int, points: Points, orientation: Orientation, radius: FloatArray | None
) -> tuple[bool, str]:
    if orientation.inlet is not None:
        inlet = np.asarray(orientation.inlet, float)
        d0, d1 = (float(np.linalg.norm(points[i] - inlet)) for i in (0, -1))
        flip, why = d1 < d0, f"l = 0 at the end nearest final.inlet ({min(d0, d1):.3g} mm from it)"
    else:
        flip, why = widest_end_flip(points, radius) or _shared_end_flip(network, index, points)
    if orientation.reverse:
        flip, why = not flip, why + "; then reversed (final.reverse: true)"
    return flip, why


def _shared_end_flip(network: CenterlineNetwork, index: int, points: Points) -> tuple[bool, str]:
    others = [assemble_path(network, i)[0] for i in network.path_ids() if i != index]
    if not others:
        return False, "l = 0 at the file's first point (a single path: give final.inlet to choose the end)"
    step = median(np.linalg.norm(np.diff(points, axis=0), axis=1))
    tol = 0.25 * step
    shared = [sum(_near(end, o, tol) for o in others) for end in (points[0], points[-1])]
    if shared[0] == shared[1]:
        return False, "l = 0 at the file's first point (neither end is shared: give final.inlet to choose)"
    return shared[1] > shared[0], f"l = 0 at the end shared with {max(shared)} other path(s) (the inlet)"


def _near(point: FloatArray, polyline: Points, tol: float) -> bool:
    return bool(np.min(np.linalg.norm(polyline - point, axis=1)) <= tol)


def _ranges(values: list[int]) -> str:
    if values == list(range(values[0], values[-1] + 1)):
        return f"{values[0]}..{values[-1]}" if len(values) > 1 else str(values[0])
    return ", ".join(map(str, values))
