"""A tetrahedral mesh of the body in its parameter domain: a cross-section swept along l in layers.

Parameter domain
    (x, y, l): the unit disk of :mod:`softdesign.meshing.volume_mesh.cross_section` (x, y
    in fractions of the section's radius along N, B) times l in [0, 1].  A
    mapping to space at some q (:mod:`softdesign.meshing.volume_mesh.sweep_body`) moves
    the nodes only, so every q has this mesh's connectivity.
Layers
    The cross-section is copied at each layer ``l_j``; node ``j * P + p`` is
    point p of layer j (before unused nodes are dropped).  A hole exists in
    the prisms between layers inside its l-range, so its ends must be layers
    (:func:`layer_grid` puts them in).
Prisms into tetrahedra
    Each prism (a, b, c) -> (A, B, C) is split into 3 tetrahedra so that each
    quadrilateral side's diagonal starts at its smallest global node index
    (Dompierre et al. 1999, "How to subdivide pyramids, prisms and hexahedra
    into tetrahedra"): the rule depends on the face alone, so the two prisms
    sharing a face cut it alike and the mesh conforms.  A three-fold
    symmetric section orders its triangles' corners by a rule of the same
    kind that turns with its rotation (``corner_order``,
    :mod:`softdesign.meshing.volume_mesh.three_fold`), so that the split commutes with it.  Every tetrahedron is
    then ordered to positive volume in (x, y, l) (VTK's order).
Named surfaces
    Boundary faces (those of one tetrahedron), outward: ``skin`` (the outer
    circle's side faces), ``base`` and ``tip`` (the end layers), and per hole
    ``<name>_wall`` (its circle's side faces) and ``<name>_cap`` (faces in a
    layer that close it); every boundary face has exactly one name.  A hole
    open at the base (tip) has an ``<name>_inlet`` (``_outlet``) lid: a fan of
    its circle's nodes in the end layer, not faces of the solid, which closes
    the cavity for a pressure constraint.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.meshing.volume_mesh.cross_section import Circle, CrossSection, cross_section, turned_gradings
from softdesign.types import FloatArray, IntArray

#: A grid value closer than this fraction of its neighbouring step to a hole's end is dropped (no slivers).
LAYER_GAP_FRACTION = 0.3


@dataclass(frozen=True)
class Hole:
    """A circular hole along part of the body: a chamber, a feed line or the port.

    Attributes
    ----------
    name : str, names its surfaces (``<name>_wall``, ``<name>_cap``, ``<name>_inlet``)
    circle : its circle in the cross-section (fractions of the section's radius)
    l_range : (l0, l1), where it exists; l0 = 0 opens it at the base, l1 = 1 at the tip
    cavity : str, holes sharing a cavity name form one closed cavity (a chamber and its feed); default ``name``
    """

    name: str
    circle: Circle
    l_range: tuple[float, float]
    cavity: str = ""

    @property
    def cavity_name(self) -> str:
        """The cavity this hole belongs to."""
        return self.cavity or self.name


@dataclass(frozen=True)
class SweptMesh:
    """The swept tetrahedral mesh in the parameter domain.

    Attributes
    ----------
    section : the cross-section
    l : (n,) float, the layers
    holes : the holes
    node_layer, node_point : (V,) int64, node k is ``section.points[node_point[k]]`` at ``l[node_layer[k]]``
    tets : (T, 4) int64, positive in (x, y, l)
    tet_layer : (T,) int64, the prism layer j (between l[j] and l[j + 1])
    faces : (F, 3) int64, boundary faces, counter-clockwise seen from outside the solid
    face_group : (F,) int64, index into ``groups``
    groups : tuple of str, the names of the boundary surfaces
    lids : dict name -> (k, 3) int64, each open hole's lid (``<name>_inlet`` at the base, ``<name>_outlet`` at
        the tip): a fan of its circle's nodes, normals into the cavity
    """

    section: CrossSection
    l: FloatArray
    holes: tuple[Hole, ...]
    node_layer: IntArray
    node_point: IntArray
    tets: IntArray
    tet_layer: IntArray
    faces: IntArray
    face_group: IntArray
    groups: tuple[str, ...]
    lids: dict[str, IntArray]

    def reference_points(self) -> FloatArray:
        """Nodes in the parameter domain, (V, 3): (x, y, l)."""
        xy = self.section.points[self.node_point]
        return np.column_stack([xy, self.l[self.node_layer]])

    def base_nodes(self) -> IntArray:
        """The nodes of the base face (layer 0), ascending."""
        return np.flatnonzero(self.node_layer == 0).astype(np.int64)

    def group_faces(self, name: str) -> IntArray:
        """The boundary faces named ``name``, (k, 3)."""
        return self.faces[self.face_group == self.groups.index(name)]

    def cavity_surface(self, cavity: str) -> IntArray:
        """The closed surface of one cavity, (k, 3), normals out of the cavity (into the solid)."""
        names = [h.name for h in self.holes if h.cavity_name == cavity]
        if not names:
            raise KeyError(f"no cavity {cavity!r}; cavities: {sorted({h.cavity_name for h in self.holes})}")
        parts = [self.group_faces(f"{n}_{part}") for n in names for part in ("wall", "cap")
                 if f"{n}_{part}" in self.groups]
        lids = [self.lids[f"{n}_{end}"] for n in names for end in ("inlet", "outlet") if f"{n}_{end}" in self.lids]
        solid_side = np.concatenate(parts + lids)
        return solid_side[:, ::-1].copy()


def layer_grid(l: npt.ArrayLike, holes: Sequence[Hole]) -> FloatArray:
    """``l`` (strictly increasing, from 0 to 1) with every hole's ends put in, near neighbours dropped."""
    grid = np.asarray(l, float)
    if grid.ndim != 1 or grid.size < 2 or grid[0] != 0.0 or grid[-1] != 1.0 or np.any(np.diff(grid) <= 0):
        raise ValueError("layer_grid: l must increase strictly from 0 to 1")
    ends = np.unique([e for h in holes for e in h.l_range if 0.0 < e < 1.0])
    step = np.interp(ends, 0.5 * (grid[1:] + grid[:-1]), np.diff(grid)) if ends.size else ends
    keep = np.ones(grid.size, bool)
    for end, h in zip(ends, step, strict=True):
        keep &= np.abs(grid - end) > LAYER_GAP_FRACTION * h
    keep[[0, -1]] = True
    return np.unique(np.concatenate([grid[keep], ends]))


def _prism_tets(bottom: IntArray, top: IntArray, key: IntArray | None = None) -> IntArray:
    """Three tetrahedra per prism (bottom (k, 3), top (k, 3), top above bottom, top indices > bottom's); each
    side's diagonal starts at the bottom corner of smaller ``key`` (k, 3) (default: ``bottom``, the nodes)."""
    key = bottom if key is None else key
    # turn each prism so that its smallest corner (a bottom node, as top > bottom) comes first
    first = np.argmin(key, axis=1)
    order = (first[:, None] + np.arange(3)) % 3
    rows = np.arange(len(bottom))[:, None]
    a, b, c = (bottom[rows, order][:, i] for i in range(3))
    A, B, C = (top[rows, order][:, i] for i in range(3))
    # side (a b B A) and (a c C A): diagonals from a; side (b c C B): from the smaller of b and c
    b_first = (key[rows, order][:, 1] < key[rows, order][:, 2])[:, None]
    t1 = np.where(b_first, np.column_stack([a, b, c, C]), np.column_stack([a, b, c, B]))
    t2 = np.where(b_first, np.column_stack([a, b, C, B]), np.column_stack([a, B, c, C]))
    t3 = np.column_stack([a, B, C, A])
    return np.stack([t1, t2, t3], axis=1).reshape(-1, 4)


def _positive(tets: IntArray, points: FloatArray) -> IntArray:
    p = points[tets]
    volume = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    if np.any(volume == 0):
        raise MeshError("swept mesh: a degenerate tetrahedron in the parameter domain; this is a bug")
    return np.where((volume < 0)[:, None], tets[:, [0, 2, 1, 3]], tets)


def _solid_triangles(section: CrossSection, l: FloatArray, holes: Sequence[Hole]) -> np.ndarray:
    """(n - 1, T) bool: triangle t is solid in prism layer j (no hole active there contains it)."""
    mid = 0.5 * (l[1:] + l[:-1])
    solid = np.ones((len(mid), len(section.triangles)), bool)
    for k, hole in enumerate(holes):
        active = (mid > hole.l_range[0]) & (mid < hole.l_range[1])
        solid &= ~(active[:, None] & section.inside[:, k][None, :])
    return solid


def sweep_mesh(section: CrossSection, l: FloatArray, holes: Sequence[Hole]) -> SweptMesh:
    """Sweep ``section`` through the layers ``l`` (see :func:`layer_grid`) with ``holes`` cut where they exist.

    Raises
    ------
    ValueError
        Holes and the section's circles differ in number, or a hole's end is not a layer.
    """
    l = np.asarray(l, float)
    if len(holes) != section.inside.shape[1]:
        raise ValueError(f"sweep_mesh: {len(holes)} holes for a section with {section.inside.shape[1]} circles")
    for h in holes:
        if not all(np.any(np.abs(l - e) < 1e-12) for e in h.l_range):
            raise ValueError(f"sweep_mesh: hole {h.name}'s ends {h.l_range} must be layers (use layer_grid)")
    P, tri = len(section.points), section.triangles
    solid = _solid_triangles(section, l, holes)
    layer, t = np.nonzero(solid)
    order = None if section.corner_order is None else section.corner_order[t]
    tets = _prism_tets(layer[:, None] * P + tri[t], (layer[:, None] + 1) * P + tri[t], order)
    tet_layer = np.repeat(layer, 3).astype(np.int64)
    used, tets = np.unique(tets, return_inverse=True)
    tets = tets.reshape(-1, 4).astype(np.int64)
    node_layer, node_point = (used // P).astype(np.int64), (used % P).astype(np.int64)
    reference = np.column_stack([section.points[node_point], l[node_layer]])
    tets = _positive(tets, reference)
    faces, groups, names = _name_faces(tets, node_layer, node_point, section, holes, len(l))
    lids = _lids(section, holes, l, used, P)
    return SweptMesh(section, l, tuple(holes), node_layer, node_point, tets, tet_layer, faces, groups, names, lids)


def _boundary_faces(tets: IntArray) -> IntArray:
    """Faces of exactly one tetrahedron, outward (tets positive)."""
    faces = np.concatenate([tets[:, [1, 2, 3]], tets[:, [0, 3, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 1]]])
    key = np.sort(faces, axis=1)
    n = int(tets.max()) + 1  # one int64 per face (n**3 < 2**63 for n < 2 million nodes): unique on rows is slow
    if n >= 2_000_000:
        raise MeshError(f"swept mesh: {n} nodes, more than the 2 million a face key holds; use a coarser mesh")
    _, first, counts = np.unique((key[:, 0] * n + key[:, 1]) * n + key[:, 2], return_index=True, return_counts=True)
    return faces[np.sort(first[counts == 1])]


def _name_faces(tets: IntArray, node_layer: IntArray, node_point: IntArray, section: CrossSection,
                holes: Sequence[Hole], layers: int) -> tuple[IntArray, IntArray, tuple[str, ...]]:
    faces = _boundary_faces(tets)
    names = ["skin", "base", "tip"] + [f"{h.name}_{part}" for h in holes for part in ("wall", "cap")]
    group = np.full(len(faces), -1, np.int64)
    fl, fp = node_layer[faces], node_point[faces]
    flat = (fl == fl[:, :1]).all(axis=1)
    on_outer = (fp < section.outer_count).all(axis=1)
    group[~flat & on_outer] = 0
    group[flat & (fl[:, 0] == 0)] = 1
    group[flat & (fl[:, 0] == layers - 1)] = 2
    for k, nodes in enumerate(section.circle_nodes):
        group[(group < 0) & ~flat & np.isin(fp, nodes).all(axis=1)] = 3 + 2 * k
    caps = np.flatnonzero((group < 0) & flat)
    if caps.size:
        centroid = section.points[fp[caps]].mean(axis=1)
        for k, h in enumerate(holes):
            inside = np.linalg.norm(centroid - np.asarray(h.circle.center), axis=1) < h.circle.radius
            free = group[caps] < 0
            group[caps[free & inside]] = 4 + 2 * k
    if np.any(group < 0):
        raise MeshError(f"swept mesh: {int(np.sum(group < 0))} boundary faces belong to no named surface; "
                        "this is a bug, please report the case")
    present = np.unique(group)
    remap = np.full(len(names), -1, np.int64)
    remap[present] = np.arange(present.size)
    return faces, remap[group], tuple(names[i] for i in present)


def _lids(section: CrossSection, holes: Sequence[Hole], l: FloatArray, used: IntArray,
          P: int) -> dict[str, IntArray]:
    """Each hole open at an end: a fan of its circle's nodes in the end layer (the nodes inside the
    circle are in no tetrahedron there), normals into the cavity as the solid's faces around it."""
    lids = {}
    for k, h in enumerate(holes):
        ring = section.circle_nodes[k]
        fan = np.column_stack([np.full(len(ring) - 2, ring[0]), ring[1:-1], ring[2:]])  # counter-clockwise: +l
        for open_end, layer, name in ((h.l_range[0] == 0.0, 0, "inlet"), (h.l_range[1] == 1.0, len(l) - 1,
                                                                           "outlet")):
            if open_end:
                tri = fan if layer == 0 else fan[:, ::-1]
                lids[f"{h.name}_{name}"] = np.searchsorted(used, layer * P + tri).astype(np.int64)
    return lids


def swept_disk(outer_count: int, holes: Sequence[Hole], size: float, l: npt.ArrayLike) -> SweptMesh:
    """:func:`cross_section` with the holes' circles, swept through :func:`layer_grid` of ``l``; circles next
    to a narrow gap get more nodes (:func:`~softdesign.meshing.volume_mesh.section_gaps.resolve_circles`)."""
    from softdesign.meshing.volume_mesh.section_gaps import resolve_circles

    # a three-fold symmetric section's orbits share their first circle's grading, turned (its nodes are those)
    circles = turned_gradings(outer_count, resolve_circles([h.circle for h in holes]), size)
    holes = [replace(h, circle=c) for h, c in zip(holes, circles, strict=True)]
    section = cross_section(outer_count, circles, size)
    return sweep_mesh(section, layer_grid(l, holes), holes)
