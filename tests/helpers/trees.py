"""Synthetic vessel trees whose path 0 is a small side branch: stand-ins of the files users bring (issue 43).

A trunk (a polyline, radius constant on each of its pieces) with straight
side branches (limbs) leaving it; written VMTK-style: one path per outlet,
each from the inlet and repeating the trunk up to its branch, in the order
asked (a small branch first, as real files often have it), with
``MaximumInscribedSphereRadius``.  The wall is the boolean union of capped
tubes (manifold3d), so every end is a flat cap; optionally labelled
(``CellEntityIds``: the wall cut into several labels, as SimVascular labels
wall faces, and one label per cap).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tests.helpers.robust_vessels import segment

#: Where a straight limb leaves the trunk, against where it starts on the trunk's axis, mm: its centre is
#: half its own radius (LEAVE_RADII) off the axis after 0.5 r / sin(angle) along it (1.5 mm for r = 3 mm
#: at 90 degrees), plus one point spacing (0.5 mm) of the written paths.
LEAVE_TOL_MM = 2.0


@dataclass(frozen=True)
class Limb:
    """A straight side branch: leaves the trunk's axis ``at_mm`` along it, towards ``direction``, mm."""

    at_mm: float
    direction: tuple[float, float, float]
    length_mm: float
    radius_mm: float


@dataclass(frozen=True)
class Tree:
    """A trunk (points (n, 3) mm, inlet first) whose radius is ``radii[k][1]`` up to arc length ``radii[k][0]``,
    and its limbs."""

    trunk: np.ndarray
    radii: tuple[tuple[float, float], ...]
    limbs: tuple[Limb, ...]

    def trunk_radius(self) -> np.ndarray:
        s = _arc(self.trunk)
        ends = np.array([end for end, _ in self.radii])
        return np.array([r for _, r in self.radii])[np.minimum(np.searchsorted(ends, s), len(ends) - 1)]

    def limb_axis(self, limb: Limb, step: float) -> np.ndarray:
        s = _arc(self.trunk)
        start = np.array([np.interp(limb.at_mm, s, self.trunk[:, k]) for k in range(3)])
        direction = np.asarray(limb.direction, float) / np.linalg.norm(limb.direction)
        return segment(start, start + limb.length_mm * direction, step)

    def paths(self, step: float = 0.5) -> list[tuple[np.ndarray, np.ndarray]]:
        """The trunk's path, then one per limb: (points, radius), each from the inlet."""
        s, radius = _arc(self.trunk), self.trunk_radius()
        out = [(self.trunk, radius)]
        for limb in self.limbs:
            head = s < limb.at_mm - 1e-9
            axis = self.limb_axis(limb, step)
            out.append((np.concatenate([self.trunk[head], axis]),
                        np.concatenate([radius[head], np.full(len(axis), limb.radius_mm)])))
        return out


def _arc(points: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def arch_trunk(ascending_mm: float = 40.0, bend_mm: float = 25.0, descending_mm: float = 120.0,
               step: float = 0.5) -> np.ndarray:
    """An aortic arch: up along +z, a half turn of radius ``bend_mm`` over the top towards +x, down along -z."""
    up = segment(np.zeros(3), np.array([0.0, 0.0, ascending_mm]), step)[:-1]
    angle = np.arange(0.0, np.pi, step / bend_mm)
    turn = np.column_stack([bend_mm * (1 - np.cos(angle)), np.zeros_like(angle),
                            ascending_mm + bend_mm * np.sin(angle)])
    top = np.array([2 * bend_mm, 0.0, ascending_mm])
    down = segment(top, top - np.array([0.0, 0.0, descending_mm]), step)
    return np.concatenate([up, turn, down])


def tube_mesh(axis: np.ndarray, radius: float, edge: float):
    """A capped tube of ``radius`` about ``axis`` (n, 3), edges about ``edge`` mm, as a manifold3d Manifold."""
    from softdesign.meshing.solids import manifold_from_mesh
    from softdesign.samples.surfaces import framed_polyline, swept_tube

    framed = framed_polyline(axis, "tube")
    rings = int(np.ceil(framed.length / edge)) + 1
    around = int(np.ceil(2 * np.pi * radius / edge))
    vertices, faces = swept_tube(framed, rings, around, np.full(2, radius), 0.0, np.zeros(2))
    return manifold_from_mesh(vertices, faces, "tube")[0]


def tree_surface(tree: Tree, edge: float) -> tuple[np.ndarray, np.ndarray, list[tuple[np.ndarray, np.ndarray]]]:
    """Vertices (V, 3), faces (F, 3) of the tree's wall, and each open end's (centre, outward axis)."""
    from softdesign.meshing.solids import checked

    s = _arc(tree.trunk)
    body, start = None, 0.0
    for end, radius in tree.radii:  # each piece reaches a little into the next, so the union is one body
        piece = tree.trunk[(s >= start - 1e-9) & (s <= min(end + 2 * edge, s[-1]) + 1e-9)]
        tube = tube_mesh(piece, radius, edge)
        body = tube if body is None else body + tube
        start = end
    ends = [(tree.trunk[0], _unit(tree.trunk[0] - tree.trunk[1]))]
    for limb in tree.limbs:
        # from the trunk's axis, so the limb's inner cap lies inside the trunk
        axis = tree.limb_axis(limb, edge / 2)
        body = body + tube_mesh(axis, limb.radius_mm, edge)
        ends.append((axis[-1], _unit(axis[-1] - axis[-2])))
    ends.append((tree.trunk[-1], _unit(tree.trunk[-1] - tree.trunk[-2])))  # the inlet, the limbs, the trunk's end
    mesh = checked(body, "tree").to_mesh64()
    return np.asarray(mesh.vert_properties, float)[:, :3], np.asarray(mesh.tri_verts, np.int64), ends


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def cap_labels(vertices: np.ndarray, faces: np.ndarray, ends: list[tuple[np.ndarray, np.ndarray]],
               wall_labels: int) -> np.ndarray:
    """CellEntityIds: the wall cut along x into ``wall_labels`` labels 1.., then each end's flat cap, in order."""
    corners = vertices[faces]
    centroids = corners.mean(axis=1)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    edges = np.quantile(centroids[:, 0], np.linspace(0.0, 1.0, wall_labels + 1)[1:-1])
    labels = 1 + np.searchsorted(edges, centroids[:, 0])
    for k, (centre, outward) in enumerate(ends):
        cap = (np.abs((centroids - centre) @ outward) < 1e-6) & (normals @ outward > 0.999)
        assert cap.any(), f"end {k} has no cap faces"
        labels[cap] = wall_labels + 1 + k
    return labels.astype(np.int32)


def write_tree(folder: Path, tree: Tree, order: list[int], *, units: str = "mm", centerline: str | None = "vtp",
               surface: str | None = "stl", edge: float = 1.0, wall_labels: int = 0) -> dict[str, Path]:
    """Write the tree's files: the centerline (``vtp``: VMTK polylines with radii; ``vtk``: gmsh-like 2-point
    segments in a legacy file, no radius; None: none), the wall (``stl``, ``vtp`` with labels when
    ``wall_labels``; None: none), coordinates in ``units``.  ``order``: the paths in the file, by their index
    in :meth:`Tree.paths` (0 the trunk, k the k-th limb).
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.types import UNIT_SCALE_TO_MM
    from tests.helpers.segment_files import segments_of, write_segments

    folder.mkdir(parents=True, exist_ok=True)
    scale = 1.0 / UNIT_SCALE_TO_MM[units]
    paths = [tree.paths()[k] for k in order]
    out: dict[str, Path] = {}
    if centerline == "vtp":
        out["centerline"] = write_polylines_vtp(folder / "centerline.vtp", [p * scale for p, _ in paths],
                                                {"MaximumInscribedSphereRadius": [r * scale for _, r in paths]})
    elif centerline == "vtk":
        points, segments = segments_of([p * scale for p, _ in paths])
        out["centerline"] = write_segments(folder / "centerline.vtk", points, segments)
    if surface is not None:
        vertices, faces, ends = tree_surface(tree, edge)
        if wall_labels:
            out["surface"] = _write_labelled(folder / "surface.vtp", vertices * scale, faces,
                                             cap_labels(vertices, faces, ends, wall_labels))
        else:
            out["surface"] = write_mesh(folder / f"surface.{surface}", vertices * scale, faces)
    return out


def _write_labelled(path: Path, vertices: np.ndarray, faces: np.ndarray, labels: np.ndarray) -> Path:
    from vtkmodules.util.numpy_support import numpy_to_vtk

    from softdesign.io.vtk_polydata import polydata_writer
    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    poly = polydata_from_triangles(vertices, faces)
    array = numpy_to_vtk(labels, deep=True)
    array.SetName("CellEntityIds")
    poly.GetCellData().AddArray(array)
    writer = polydata_writer(poly)
    writer.SetFileName(str(path))
    assert writer.Write() == 1
    return path
