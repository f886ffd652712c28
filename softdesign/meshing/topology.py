"""Topology and size of triangle meshes: edges, watertightness, winding, shells, volume, area.

A mesh is plain arrays: vertices (V, 3) float, mm, and faces (F, 3) int.

Definitions
    watertight          every undirected edge belongs to exactly two faces
    winding_consistent  watertight, and every directed edge occurs once and its
                        reverse once, so neighbouring faces agree on orientation
    vertex_manifold     the faces around every vertex form a single fan
    shells              connected pieces of surface; a shell of positive
                        signed volume bounds a body, one of negative signed
                        volume (wound inwards) bounds a void inside a body
    euler               V - E + F = sum over shells of 2 - 2 genus: 2 for a
                        solid body, 4 for a body with one sealed internal
                        void (two spheres), 2 again once a port opens it
    volume, area        signed volume sum of v0 . (v1 x v2) / 6 (about the
                        vertex centroid, for round-off) over each shell, the
                        shells' volumes summed; and total face area
    boundary            edges of one face only; they chain into boundary
                        loops (the open ends of a vessel surface)

trimesh has the same definitions, but its volume integrates about the
origin and in another order; the figures here are the ones every build has
written, to the last bit, and need numpy and scipy only (scipy imported
where used, so that importing the command line stays quick).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.geometry.edges import EdgeTable, corner_planes, edge_keys, run_starts
from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class MeshTopology:
    """What :func:`mesh_topology` measures; definitions in the module notes.

    Attributes
    ----------
    vertices : int -- vertices used by a face
    faces : int
    edges : int -- undirected edges
    watertight, winding_consistent, vertex_manifold : bool
    shell_volumes : (shells,) float, mm^3 -- signed, shells numbered by their lowest vertex
    face_areas : (F,) float, mm^2
    """

    vertices: int
    faces: int
    edges: int
    watertight: bool
    winding_consistent: bool
    vertex_manifold: bool
    shell_volumes: FloatArray
    face_areas: FloatArray

    @property
    def shells(self) -> int:
        """Connected pieces of surface."""
        return len(self.shell_volumes)

    @property
    def bodies(self) -> int:
        """Shells of positive signed volume."""
        return int(np.sum(self.shell_volumes > 0))

    @property
    def voids(self) -> int:
        """Shells of negative signed volume (wound inwards)."""
        return int(np.sum(self.shell_volumes < 0))

    @property
    def euler(self) -> int:
        """V - E + F over the used vertices."""
        return int(self.vertices - self.edges + self.faces)

    @property
    def volume(self) -> float:
        """Signed enclosed volume, mm^3: the shells' volumes summed."""
        return float(self.shell_volumes.sum())

    @property
    def area(self) -> float:
        """Total face area, mm^2."""
        return float(self.face_areas.sum())


@dataclass(frozen=True)
class SurfaceInfo:
    """Counts and topology of a surface.

    Attributes
    ----------
    vertices, faces : counts
    boundary_edges : edges used by one face only
    boundary_loops : connected chains of boundary edges (open vessel ends)
    nonmanifold_edges : edges used by more than two faces
    capped : True when closed (no boundary and no non-manifold edge)
    bounds : (2, 3) float, mm, min and max corner
    """

    vertices: int
    faces: int
    boundary_edges: int
    boundary_loops: int
    nonmanifold_edges: int
    capped: bool
    bounds: FloatArray

    def as_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "vertices": self.vertices,
            "faces": self.faces,
            "boundary_edges": self.boundary_edges,
            "boundary_loops": self.boundary_loops,
            "nonmanifold_edges": self.nonmanifold_edges,
            "capped": self.capped,
            "bounds_mm": self.bounds.tolist(),
        }


def mesh_topology(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> MeshTopology:
    """Edges, orientation, shells, volume and area of a triangle mesh in one pass.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int

    Raises
    ------
    ValueError
        Arrays of the wrong shape, or faces that refer to missing vertices.
    """
    vertices, faces = _checked_arrays(vertices, faces)
    n = vertices.shape[0]
    used = np.flatnonzero(np.bincount(faces.ravel(), minlength=n))
    twin, watertight, consistent, n_edges = _half_edges(faces, n)
    manifold = consistent and twin is not None and _vertex_manifold(twin, used.size)  # twin: None unless consistent
    centroid = (vertices if used.size == n else vertices[used]).mean(axis=0)
    corners = corner_planes(vertices, faces)
    return MeshTopology(
        vertices=int(used.size),
        faces=int(faces.shape[0]),
        edges=n_edges,
        watertight=watertight,
        winding_consistent=consistent,
        vertex_manifold=bool(manifold),
        shell_volumes=_shell_volumes(faces, tuple(c - centroid[:, None] for c in corners), n, used),
        face_areas=0.5 * _double_areas(*corners),
    )


def face_areas(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> FloatArray:
    """Area of each face, (F,) float, mm^2."""
    return 0.5 * _double_areas(*corner_planes(np.asarray(vertices, float), np.asarray(faces, np.int64)))


def surface_area(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> float:
    """Total face area, mm^2."""
    return float(face_areas(vertices, faces).sum())


def signed_volume(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> float:
    """Volume enclosed by a closed mesh, mm^3: positive when wound outwards (divergence theorem)."""
    return mesh_topology(vertices, faces).volume


def is_watertight(faces: npt.ArrayLike) -> bool:
    """True when every undirected edge belongs to exactly two faces (vertices must be merged)."""
    faces = np.asarray(faces, np.int64)
    return _half_edges(faces, int(faces.max(initial=-1)) + 1)[1]


def is_winding_consistent(faces: npt.ArrayLike) -> bool:
    """True when watertight and the two faces of every edge run it in opposite directions.

    That is closed, edge-manifold and consistently oriented: what an enclosed
    volume needs.  Vertices must be merged (an STL read without merging is
    never watertight).
    """
    faces = np.asarray(faces, np.int64)
    return _half_edges(faces, int(faces.max(initial=-1)) + 1)[2]


def edge_uses(faces: npt.ArrayLike, n_vertices: int) -> tuple[IntArray, IntArray]:
    """Every undirected edge once and the number of faces that use it.

    Returns
    -------
    edges : (E, 2) int64, vertex indices, smaller first, sorted
    uses : (E,) int64
    """
    faces = np.asarray(faces, np.int64)
    key = np.sort(edge_keys(faces, n_vertices))
    if key.size == 0:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    starts = run_starts(key)
    edge = key[starts]
    uses = np.diff(np.append(starts, key.size))
    return np.column_stack([edge // n_vertices, edge % n_vertices]), uses


def drop_unused_vertices(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> tuple[FloatArray, IntArray]:
    """The vertices that faces use, in their order, and the faces renumbered to them.

    Returns
    -------
    vertices : (U, 3) float, mm
    faces : (F, 3) int64
    """
    used, compact = np.unique(np.asarray(faces, np.int64), return_inverse=True)
    return np.asarray(vertices, float)[used], compact.reshape(-1, 3)


def describe_surface(vertices: npt.ArrayLike, faces: npt.ArrayLike, table: EdgeTable | None = None) -> SurfaceInfo:
    """Topology summary of a surface that may be open or non-manifold (vertices (V, 3) mm, faces (F, 3)).

    ``table``: the faces' :class:`~softdesign.geometry.edges.EdgeTable` on V vertices, when the caller has it
    (the ingest's end planes use the same one): its groups are :func:`edge_uses`' edges and counts, not sorted again.
    """
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    count = max(len(vertices), int(faces.max(initial=-1)) + 1)
    if table is not None and table.n_vertices == count and len(table.keys) == faces.size and faces.size:
        edges, uses = table.edges(), table.uses
    else:
        edges, uses = edge_uses(faces, count)
    boundary = edges[uses == 1]
    loops = 0
    if len(boundary):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        nodes, local = np.unique(boundary, return_inverse=True)
        local = local.reshape(-1, 2)
        graph = coo_matrix((np.ones(len(local)), (local[:, 0], local[:, 1])), shape=(len(nodes),) * 2)
        loops = int(connected_components(graph, directed=False)[0])
    nonmanifold = int(np.count_nonzero(uses > 2))
    return SurfaceInfo(
        vertices=int(len(vertices)),
        faces=int(len(faces)),
        boundary_edges=int(len(boundary)),
        boundary_loops=loops,
        nonmanifold_edges=nonmanifold,
        capped=len(boundary) == 0 and nonmanifold == 0,
        bounds=np.array([np.min(vertices, axis=0), np.max(vertices, axis=0)]),
    )


def _checked_arrays(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> tuple[FloatArray, IntArray]:
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"expected vertices (V, 3) and faces (F, 3), got {vertices.shape} and {faces.shape}")
    if faces.size and (faces.min() < 0 or faces.max() >= vertices.shape[0]):
        raise ValueError("faces refer to vertices that do not exist")
    return vertices, faces


def _half_edge_keys(faces: IntArray, n_vertices: int) -> IntArray:
    """Key ``2 (min(a, b) V + max(a, b)) + (a > b)`` of half-edge j = 3f + p, a = faces[f, p] -> b = faces[f, p + 1]:
    twice its edge's :func:`~softdesign.geometry.edges.edge_keys`, plus its direction."""
    return 2 * edge_keys(faces, n_vertices) + (faces.ravel() > faces[:, [1, 2, 0]].ravel())


def _half_edges(faces: IntArray, n_vertices: int) -> tuple[IntArray | None, bool, bool, int]:
    """Each half-edge's twin (None unless the winding is consistent), watertight, winding consistent, edge count.

    Sorted, the keys of :func:`_half_edge_keys` put the half-edges of one
    undirected edge next to each other.  Watertight: the sorted keys come in
    pairs of one edge each.  Consistent: each pair is a -> b and b -> a (keys
    2k and 2k + 1), which then are each other's twins.
    """
    key = _half_edge_keys(faces, n_vertices)
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
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    step = np.roll(twin.reshape(-1, 3), -1, axis=1).ravel()  # twin of the next half-edge
    n = step.size
    graph = csr_matrix((np.ones(n), step, np.arange(n + 1)), shape=(n, n))  # row j: the one step from j
    fans = connected_components(graph, directed=False)[0]
    return fans == used


def _shell_volumes(faces: IntArray, corners: tuple[FloatArray, FloatArray, FloatArray], n_vertices: int,
                   used: IntArray) -> FloatArray:
    """Each connected shell's signed volume (mm^3), corners (:func:`corner_planes`) mm about the centroid."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

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
    products = _cross(corners[1], corners[2])
    products *= corners[0]
    # v0 . (v1 x v2): x + z, then + y, the order in which np.einsum("ij,ij->i") adds a last axis of 3 (its two
    # SIMD lanes), as the volumes every build has written were added
    tet = products[0] + products[2]
    tet += products[1]
    tet /= 6.0
    count = int(relabel.max()) + 1 if used.size else 0
    # weighted counts are float64 (the stubs type every bincount as int)
    return np.asarray(np.bincount(shell_of_vertex[faces[:, 0]], weights=tet, minlength=count), np.float64)


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """u x v of (3, n) coordinate rows: np.cross's products in its order, without its generality's overhead."""
    out = np.empty(u.shape)
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.multiply(u[j], v[k], out=out[i])
        out[i] -= u[k] * v[j]
    return out


def _double_areas(p0: FloatArray, p1: FloatArray, p2: FloatArray) -> FloatArray:
    """Twice the area of each face (F,), mm^2, from its corners as (3, F) rows (:func:`corner_planes`), mm.

    The three squares are added x + y, then + z, as ``np.linalg.norm`` adds them over a last axis of 3.
    """
    normal = _cross(p1 - p0, p2 - p0)
    normal *= normal
    out = normal[0] + normal[1]
    out += normal[2]
    return np.sqrt(out, out=out)
