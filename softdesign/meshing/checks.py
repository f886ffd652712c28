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
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from softdesign.errors import MeshError
from softdesign.types import FloatArray, IntArray

#: Largest |mesh volume / integrated volume - 1| a kept mesh may have (issue 5).
VOLUME_RTOL = 0.005
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


def _edges(faces: IntArray, n_vertices: int) -> tuple[IntArray, IntArray, bool, bool, int]:
    """Half-edges sorted by key (their order and keys), watertight, winding consistent, undirected edge count.

    Half-edge j = 3f + p runs from faces[f, p] to faces[f, (p + 1) % 3]; its key is a * V + b.
    """
    half = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    undirected = np.sort(np.minimum(half[:, 0], half[:, 1]) * n_vertices + np.maximum(half[:, 0], half[:, 1]))
    starts = np.flatnonzero(np.concatenate([[True], undirected[1:] != undirected[:-1]]))
    counts = np.diff(np.append(starts, undirected.size))
    directed = half[:, 0] * n_vertices + half[:, 1]
    order = np.argsort(directed, kind="stable")
    keys = directed[order]
    watertight = bool(np.all(counts == 2))
    # two half-edges on each edge with distinct keys can only be a -> b and b -> a
    consistent = watertight and bool(np.all(keys[1:] != keys[:-1]))
    return order, keys, watertight, consistent, int(starts.size)


def _vertex_manifold(faces: IntArray, order: IntArray, keys: IntArray, n_vertices: int, used: int) -> bool:
    """True when the face corners around each vertex join into a single fan (needs consistent winding).

    Half-edge j = 3f + p runs a -> b; its twin b -> a is half-edge 3g + p'; the
    corners of a in f (3f + p) and in g (3g + (p' + 1) % 3) are neighbours in a's fan.
    """
    half = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    twin = order[np.searchsorted(keys, half[:, 1] * n_vertices + half[:, 0])]
    neighbour = 3 * (twin // 3) + (twin % 3 + 1) % 3
    n = twin.size
    graph = coo_matrix((np.ones(n), (np.arange(n), neighbour)), shape=(n, n))
    fans = connected_components(graph, directed=False)[0]
    return fans == used


def _shells(vertices: FloatArray, faces: IntArray, used: IntArray) -> tuple[int, FloatArray]:
    """Number of connected shells and each shell's signed volume (mm^3)."""
    n = vertices.shape[0]
    rows = faces[:, [0, 1, 2]].ravel()
    cols = faces[:, [1, 2, 0]].ravel()
    graph = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    relabel = np.unique(labels[used], return_inverse=True)[1]  # components numbered over used vertices
    shell_of_vertex = np.zeros(n, np.int64)
    shell_of_vertex[used] = relabel
    p = vertices - vertices[used].mean(axis=0)
    tet = np.einsum("ij,ij->i", p[faces[:, 0]], np.cross(p[faces[:, 1]], p[faces[:, 2]])) / 6.0
    count = int(relabel.max()) + 1 if used.size else 0
    return count, np.bincount(shell_of_vertex[faces[:, 0]], weights=tet, minlength=count)


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
    order, keys, watertight, consistent, n_edges = _edges(faces, n)
    manifold = consistent and _vertex_manifold(faces, order, keys, n, used.size)
    cross = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    double_area = np.linalg.norm(cross, axis=1)
    edge_sq = np.mean(np.sum(np.diff(vertices[faces[:, [0, 1, 2, 0]]], axis=1) ** 2, axis=-1)) if faces.size else 0.0
    shells, shell_volume = _shells(vertices, faces, used)
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
            "refine the tessellation: more angles (an na-gon holds sin(2 pi/na)/(2 pi/na) of a circle's area) "
            "or rings closer together"
            if only_volume and report.volume > 0
            else "this is a bug in the mesher; please report it with the case file"
        )
        raise MeshError(f"{label}: the mesh is not a valid solid: " + "; ".join(problems) + f"; {fix}")
    return report
