"""Checks every mesh passes before it is kept: closed, oriented, one body, the right topology and volume.

Definitions (vertices (V, 3) mm, faces (F, 3) int)
    watertight          every undirected edge belongs to exactly two faces
    winding_consistent  every directed edge occurs once and its reverse once,
                        so neighbouring faces agree on orientation
    vertex_manifold     the faces around every vertex form a single fan
    shells              connected pieces of surface; a shell of positive
                        signed volume bounds a body, one of negative signed
                        volume (wound inwards) bounds a void inside a body
    euler               V - E + F = sum over shells of 2 - 2 genus: 2 for a
                        solid body, 4 for a body with one sealed internal
                        void (two spheres), 2 again once a port opens it
    volume, area        signed volume sum of v0 . (v1 x v2) / 6 (about the
                        vertex centroid, for round-off), and total face area
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import numpy.typing as npt
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from softdesign.errors import MeshError
from softdesign.meshing.volume import polygon_area_ratio
from softdesign.types import FloatArray, IntArray

#: Largest |mesh volume / integrated volume - 1| a kept mesh may have (issue 5).
VOLUME_RTOL = 0.005


def fewest_sides_within(rtol: float) -> int:
    """The least na whose inscribed regular na-gon misses at most ``rtol`` of its circle's area.

    The na-gon holds sin(h) / h of the circle (h = 2 pi / na, see
    :func:`~softdesign.meshing.volume.polygon_area_ratio`), about 1 - h^2 / 6,
    so na is near 2 pi / sqrt(6 rtol); the loop settles the exact integer.
    """
    na = 3
    while 1.0 - polygon_area_ratio(na) > rtol:
        na += 1
    return na


#: Fewest vertices around a section (``export.angular_count``) the volume check can accept: 37 for
#: VOLUME_RTOL = 0.005.  The mesh's rings are polygons inscribed in the surface while the volume it is
#: checked against is integrated from the smooth surface, so even a straight round tube meshes
#: sin(h) / h of its volume (h = 2 pi / na): 36 sides lose 0.507 %, 37 lose 0.480 %.  Fewer sides
#: are bound to fail the check; a bent or elliptical section loses more than a round one and may need
#: more (the check's message says which key to raise).
MIN_ANGULAR_COUNT = fewest_sides_within(VOLUME_RTOL)

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


def _edges(faces: IntArray, n_vertices: int) -> tuple[IntArray | None, bool, bool, int]:
    """Each half-edge's twin (None unless the winding is consistent), watertight, winding consistent, edge count.

    Half-edge j = 3f + p runs a = faces[f, p] -> b = faces[f, (p + 1) % 3]; its key
    2 (min(a, b) V + max(a, b)) + (a > b) puts the half-edges of one undirected edge
    next to each other once sorted.  Watertight: the sorted keys come in pairs of
    one edge each.  Consistent: each pair is a -> b and b -> a (keys 2k and 2k + 1),
    which then are each other's twins.
    """
    start, end = faces.ravel(), np.roll(faces, -1, axis=1).ravel()
    key = 2 * (np.minimum(start, end) * n_vertices + np.maximum(start, end)) + (start > end)
    order = np.argsort(key, kind="stable")  # a tessellation's keys come in long sorted runs
    keys = key[order]
    edge = keys >> 1
    new_edge = edge[1:] != edge[:-1]
    watertight = keys.size > 0 and keys.size % 2 == 0 and not new_edge[0::2].any() and bool(new_edge[1::2].all())
    consistent = watertight and bool(np.all(keys[0::2] != keys[1::2]))
    n_edges = int(np.count_nonzero(new_edge)) + 1
    if not consistent:
        return None, watertight, consistent, n_edges
    twin = np.empty_like(order)
    twin[order[0::2]] = order[1::2]
    twin[order[1::2]] = order[0::2]
    return twin, watertight, consistent, n_edges


def _vertex_manifold(twin: IntArray, used: int) -> bool:
    """True when the faces around each vertex join into a single fan (needs consistent winding).

    Half-edge j = 3f + p runs a -> b; the next half-edge of f leaves b, and its
    twin, in the neighbouring face around b, ends at b again.  Repeating that
    step walks once round the faces of b that share edges with f: one cycle
    per fan, so a 2-manifold has exactly as many cycles as used vertices.
    """
    step = np.roll(twin.reshape(-1, 3), -1, axis=1).ravel()  # twin of the next half-edge
    n = step.size
    graph = csr_matrix((np.ones(n), step, np.arange(n + 1)), shape=(n, n))  # row j: the one step from j
    fans = connected_components(graph, directed=False)[0]
    return fans == used


def _shells(faces: IntArray, corners: FloatArray, n_vertices: int, used: IntArray) -> tuple[int, FloatArray]:
    """Number of connected shells and each shell's signed volume (mm^3), corners (F, 3, 3) mm about the centroid."""
    n, count_faces = n_vertices, faces.shape[0]
    # one graph of vertices (nodes 0 .. V-1, so components are numbered as over vertices alone)
    # and faces (nodes V ..), each face joined to its three vertices: CSR rows without a sort
    indptr = np.concatenate([np.zeros(n, np.int64), np.arange(0, faces.size + 1, 3)])
    graph = csr_matrix((np.ones(faces.size), faces.ravel(), indptr), shape=(n + count_faces, n + count_faces))
    labels = connected_components(graph, directed=False)[1][:n]
    # components numbered over used vertices (when all are used, they already are)
    relabel = labels if used.size == n else np.unique(labels[used], return_inverse=True)[1]
    shell_of_vertex = np.zeros(n, np.int64)
    shell_of_vertex[used] = relabel
    tet = np.einsum("ij,ij->i", corners[:, 0], _cross(corners[:, 1], corners[:, 2])) / 6.0
    count = int(relabel.max()) + 1 if used.size else 0
    return count, np.bincount(shell_of_vertex[faces[:, 0]], weights=tet, minlength=count)


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """Row-wise u x v of (n, 3) arrays: np.cross's products in its order, without its generality's overhead."""
    out = np.empty(u.shape)
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.subtract(u[:, j] * v[:, k], u[:, k] * v[:, j], out=out[:, i])
    return out


def _face_sizes(corners: FloatArray) -> tuple[FloatArray, float]:
    """Twice the area of each face (F,) and the mean squared edge length, mm^2, from corners (F, 3, 3) mm.

    Sums of three squares are added x + y, then + z, as ``np.linalg.norm`` and
    ``np.sum`` over a last axis of 3 add them; whole columns at a time are cheaper.
    """
    p0, p1, p2 = corners[:, 0], corners[:, 1], corners[:, 2]
    normal = _cross(p1 - p0, p2 - p0)
    normal *= normal
    double_area = np.sqrt(normal[:, 0] + normal[:, 1] + normal[:, 2])
    if not corners.size:
        return double_area, 0.0
    edge_sq = np.empty(corners.shape[:2])  # (F, 3), edges p0 p1, p1 p2, p2 p0
    for i, (a, b) in enumerate(((p0, p1), (p1, p2), (p2, p0))):
        d = b - a
        d *= d
        edge_sq[:, i] = d[:, 0] + d[:, 1] + d[:, 2]
    return double_area, float(np.mean(edge_sq))


def inspect_mesh(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, volume_expected: float | None = None
) -> MeshReport:
    """Measure a triangle mesh against the definitions in the module notes.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    volume_expected : float, optional, mm^3

    Returns
    -------
    MeshReport
    """
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"expected vertices (V, 3) and faces (F, 3), got {vertices.shape} and {faces.shape}")
    if faces.size and (faces.min() < 0 or faces.max() >= vertices.shape[0]):
        raise ValueError("faces refer to vertices that do not exist")
    n = vertices.shape[0]
    used = np.flatnonzero(np.bincount(faces.ravel(), minlength=n))
    twin, watertight, consistent, n_edges = _edges(faces, n)
    manifold = consistent and _vertex_manifold(twin, used.size)
    corners = np.take(vertices, faces, axis=0)  # (F, 3, 3); take gathers rows faster than vertices[faces]
    double_area, edge_sq = _face_sizes(corners)
    centroid = (vertices if used.size == n else vertices[used]).mean(axis=0)
    shells, shell_volume = _shells(faces, corners - centroid, n, used)
    volume = float(shell_volume.sum())
    rel = None if volume_expected is None else volume / volume_expected - 1.0
    return MeshReport(
        vertices=int(used.size),
        faces=int(faces.shape[0]),
        watertight=watertight,
        winding_consistent=consistent,
        vertex_manifold=bool(manifold),
        degenerate_faces=int(np.sum(double_area <= 2.0 * DEGENERATE_AREA_FRACTION * edge_sq)),
        shells=shells,
        bodies=int(np.sum(shell_volume > 0)),
        voids=int(np.sum(shell_volume < 0)),
        euler=int(used.size - n_edges + faces.shape[0]),
        volume=volume,
        area=float(0.5 * double_area.sum()),
        volume_expected=None if volume_expected is None else float(volume_expected),
        volume_rel_error=None if rel is None else float(rel),
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
