"""Checks every mesh passes before it is kept: closed, oriented, one body, the right topology and volume.

The figures (watertight, winding_consistent, vertex_manifold, shells,
bodies and voids, euler, volume, area) are defined and measured in
:mod:`softdesign.meshing.topology`; here they are held against what a solid
must be, with degenerate faces (vertices (V, 3) mm, faces (F, 3) int).

As written (issue 43): STL, PLY and glTF keep float32 coordinates, and a
slicer or a user's check merges coincident vertices (trimesh's
``process=True``).  :func:`written_defects` rounds the vertices to float32,
merges those that coincide and counts the faces of zero area and the edges
shared by more than two faces (non-manifold); a solid must have none of either.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.geometry.edges import corner_planes, row_cross
from softdesign.geometry.rows import rows_all_distinct, rows_in_first_order
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_tolerance import MIN_ANGULAR_COUNT, VOLUME_RTOL
from softdesign.types import FloatArray

#: A face with area below this fraction of the mean squared edge length counts as degenerate.
DEGENERATE_AREA_FRACTION = 1e-12


@dataclass(frozen=True)
class MeshReport:
    """What :func:`inspect_mesh` found; every figure goes into the manifest (:meth:`as_dict`)."""

    vertices: int
    faces: int
    watertight: bool
    winding_consistent: bool
    vertex_manifold: bool
    degenerate_faces: int
    shells: int
    bodies: int
    voids: int
    euler: int
    volume: float
    area: float
    volume_expected: float | None = None
    volume_rel_error: float | None = None
    zero_area_faces: int = 0
    nonmanifold_edges: int = 0

    def as_dict(self) -> dict[str, object]:
        """Plain JSON-ready values."""
        return asdict(self)


@dataclass(frozen=True)
class Expectation:
    """What a solid must satisfy besides being closed and oriented.

    Attributes
    ----------
    volume : float or None, mm^3
        Integrated from the parametric surface; None skips the comparison.
    euler : int
        2 for a solid body, 4 for a body with a sealed chamber.
    bodies : int
    volume_rtol : float
    """

    volume: float | None = None
    euler: int = 2
    bodies: int = 1
    volume_rtol: float = VOLUME_RTOL


def _mean_squared_edge(p0: FloatArray, p1: FloatArray, p2: FloatArray) -> float:
    """Mean squared edge length, mm^2, of faces with corners as (3, F) rows (the scale of a degenerate face).

    Sums of three squares are added x + y, then + z, as ``np.sum`` over a
    last axis of 3 adds them, into (F, 3) rows that ``np.mean`` adds up as before.
    """
    if not p0.size:
        return 0.0
    edge_sq = np.empty((p0.shape[1], 3))  # (F, 3), edges p0 p1, p1 p2, p2 p0
    for i, (a, b) in enumerate(((p0, p1), (p1, p2), (p2, p0))):
        d = b - a
        d *= d
        total = d[0] + d[1]
        total += d[2]
        edge_sq[:, i] = total
    return float(np.mean(edge_sq))


def written_defects(vertices: npt.ArrayLike, faces: npt.ArrayLike, watertight: bool = False) -> tuple[int, int]:
    """(zero-area faces, non-manifold edges: shared by more than two faces) of the mesh as written in float32 and
    read with coincident vertices merged (see the module notes); both 0 for a 2-manifold whose vertices stay
    apart in float32 (an open surface's boundary edges are no concern here: watertight says that).

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    watertight : the faces as given are known to use every edge exactly twice
        (:func:`~softdesign.meshing.topology.mesh_topology`'s ``watertight``): when float32 merges no vertices,
        no edge can then be in more than two faces, and the edges are not counted again
    """
    rounded = np.asarray(vertices, np.float32).astype(np.float64)
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    if not faces.size:
        return 0, 0
    zero = _zero_area_faces(rounded, faces)
    if watertight and rows_all_distinct(rounded):  # nothing merged: the edges are the faces' own, each in two
        return zero, 0
    first, inverse = rows_in_first_order(rounded)  # coincident vertices as one (np.unique's groups, faster)
    merged = inverse[faces]
    edges = np.sort(np.concatenate([merged[:, [0, 1]], merged[:, [1, 2]], merged[:, [2, 0]]]), axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]  # a folded face's point-edge is no edge
    keys = np.sort(edges[:, 0] * np.int64(len(rounded)) + edges[:, 1])  # one integer per edge (< V^2 < 2^63)
    runs = np.diff(np.flatnonzero(np.diff(keys, prepend=-1, append=-1)))  # faces sharing each edge
    return zero, int(np.sum(runs > 2))


def _zero_area_faces(vertices: FloatArray, faces: npt.NDArray[np.int64]) -> int:
    """How many faces have a zero cross product (p1 - p0) x (p2 - p0): every square of it zero, which is when its
    length (``np.linalg.norm``, a sum of the squares) is zero; coordinate rows, ``np.cross``'s products."""
    p0, p1, p2 = corner_planes(vertices, faces)
    cross = row_cross(p1 - p0, p2 - p0)
    cross *= cross
    return int(np.count_nonzero(np.all(cross == 0.0, axis=0)))


def inspect_mesh(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, volume_expected: float | None = None
) -> MeshReport:
    """The figures of :func:`~softdesign.meshing.topology.mesh_topology`, degenerate faces and the volume error.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    volume_expected : float, optional, mm^3

    Returns
    -------
    MeshReport
    """
    topology = mesh_topology(vertices, faces)
    corners = corner_planes(np.asarray(vertices, float), np.asarray(faces, np.int64))
    degenerate = topology.face_areas <= DEGENERATE_AREA_FRACTION * _mean_squared_edge(*corners)
    rel = None if volume_expected is None else topology.volume / volume_expected - 1.0
    zero_area, nonmanifold = written_defects(vertices, faces, watertight=topology.watertight)
    return MeshReport(
        vertices=topology.vertices,
        faces=topology.faces,
        watertight=topology.watertight,
        winding_consistent=topology.winding_consistent,
        vertex_manifold=topology.vertex_manifold,
        degenerate_faces=int(np.sum(degenerate)),
        shells=topology.shells,
        bodies=topology.bodies,
        voids=topology.voids,
        euler=topology.euler,
        volume=topology.volume,
        area=topology.area,
        volume_expected=None if volume_expected is None else float(volume_expected),
        volume_rel_error=None if rel is None else float(rel),
        zero_area_faces=zero_area,
        nonmanifold_edges=nonmanifold,
    )


def _failures(report: MeshReport, expected: Expectation) -> list[str]:
    problems = []
    if not report.watertight:
        problems.append("not watertight (an edge is not shared by exactly two faces)")
    if report.watertight and not report.winding_consistent:
        problems.append("inconsistent winding (neighbouring faces disagree on orientation)")
    if report.winding_consistent and not report.vertex_manifold:
        problems.append("a vertex joins separate fans of faces (not a 2-manifold)")
    if report.degenerate_faces:
        problems.append(f"{report.degenerate_faces} degenerate (zero-area) faces")
    if report.zero_area_faces or report.nonmanifold_edges:
        problems.append(f"as written in single precision (STL) with coincident vertices merged: "
                        f"{report.zero_area_faces} zero-area faces, {report.nonmanifold_edges} non-manifold edges")
    if report.bodies != expected.bodies:
        problems.append(f"{report.bodies} bodies ({report.shells} shells), expected {expected.bodies}")
    if report.euler != expected.euler:
        problems.append(f"Euler characteristic {report.euler}, expected {expected.euler}")
    if not report.volume > 0:
        problems.append(f"volume {report.volume:.6g} mm^3, expected > 0 (faces wound inwards?)")
    if report.volume_rel_error is not None and not abs(report.volume_rel_error) <= expected.volume_rtol:
        problems.append(
            f"volume {report.volume:.6g} mm^3 differs from the integrated {report.volume_expected:.6g} mm^3 by "
            f"{100 * report.volume_rel_error:+.3f}%, expected within {100 * expected.volume_rtol:g}%"
        )
    return problems


def check_solid(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, expected: Expectation = Expectation(), label: str = "mesh"
) -> MeshReport:
    """Inspect a solid and raise when any check fails.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    expected : Expectation
    label : str
        Names the mesh in the message (e.g. ``q=0.500``).

    Raises
    ------
    MeshError
        Listing every failed check with its figures.
    """
    report = inspect_mesh(vertices, faces, expected.volume)
    problems = _failures(report, expected)
    if problems:
        only_volume = len(problems) == 1 and report.volume_rel_error is not None and problems[0].startswith("volume ")
        fix = (
            "refine the tessellation: more angles (export.angular_count; an na-gon holds sin(2 pi/na)/(2 pi/na) "
            f"of a circle's area, so a round section needs at least {MIN_ANGULAR_COUNT} and a bent or elliptical "
            "one more) or rings closer together (export.spacing_mm)"
            if only_volume and report.volume > 0
            else "this is a bug in the mesher; please report it with the case file"
        )
        raise MeshError(f"{label}: the mesh is not a valid solid: " + "; ".join(problems) + f"; {fix}")
    return report
