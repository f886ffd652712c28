"""A synthetic branching tree for benchmarks: hundreds of tracts and about a million surface triangles.

Issue 43 (item 7): a 508-tract SimVascular tree took 86 s to ingest and
175-235 s to fit one path.  This is its stand-in: a binary tree of
``depth`` levels (``2 ** (depth + 1) - 1`` segments, the tracts; 511 for
depth 8) from a root along +z.  Each child leaves its parent's end at
``branch_deg`` to the parent's direction, the branching plane turning a
quarter turn per level (so subtrees spread in 3-D); lengths shrink by
``length_ratio`` and radii by Murray's law (``2 ** (-1/3)``) per level.
A segment is a quadratic Bezier curve that leaves along its parent's
direction, so every root-to-leaf path is tangent-continuous, as VMTK's
centerlines are through a bifurcation.  The centerline file has one
polyline per leaf, root to leaf, its shared trunk repeated (VMTK's
convention); the wall is the union of every segment's capped tube
(manifold3d), tessellated so its triangle count is about ``triangles``.
Pure geometry, mm; the writer is :func:`softdesign.samples.files.write_tree`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, IntArray, Points

#: Murray's law for a symmetric split: each child's radius is the parent's times this.
MURRAY_RATIO = 2.0 ** (-1.0 / 3.0)
#: Points per mm along a segment's centerline.
POINTS_PER_MM = 2.0


@dataclass(frozen=True)
class TreeShape:
    """Parameters of the tree (mm, degrees): the root's length and radius, the levels, the ratios."""

    depth: int = 8
    root_length_mm: float = 30.0
    root_radius_mm: float = 6.0
    length_ratio: float = 0.8
    branch_deg: float = 30.0


@dataclass(frozen=True)
class TreeVessel:
    """Segments (tracts) of the tree and its root-to-leaf paths.

    Attributes
    ----------
    segments : (k, 3) points of each segment, mm, proximal first
    radii : the radius of each segment, mm
    paths : per leaf, the segment indices from the root
    """

    segments: tuple[Points, ...]
    radii: tuple[float, ...]
    paths: tuple[tuple[int, ...], ...]

    def path_points(self, leaf: int) -> tuple[Points, FloatArray]:
        """Points (n, 3) mm and radius (n,) mm of one root-to-leaf path (junction points not repeated)."""
        ids = self.paths[leaf]
        points = [self.segments[ids[0]]] + [self.segments[i][1:] for i in ids[1:]]
        radius = [np.full(len(self.segments[ids[0]]), self.radii[ids[0]])]
        radius += [np.full(len(self.segments[i]) - 1, self.radii[i]) for i in ids[1:]]
        return np.concatenate(points), np.concatenate(radius)


def _bezier(start: FloatArray, tangent: FloatArray, end: FloatArray) -> Points:
    """A quadratic Bezier from ``start`` (leaving along ``tangent``) to ``end``, about POINTS_PER_MM per mm."""
    length = float(np.linalg.norm(end - start))
    control = start + 0.5 * length * tangent
    t = np.linspace(0.0, 1.0, max(int(np.ceil(POINTS_PER_MM * length * 1.1)), 3))[:, None]
    return (1 - t) ** 2 * start + 2 * (1 - t) * t * control + t**2 * end


def _rotate(vector: FloatArray, axis: FloatArray, angle: float) -> FloatArray:
    """Rodrigues' rotation of ``vector`` about the unit ``axis`` by ``angle`` rad."""
    return (vector * np.cos(angle) + np.cross(axis, vector) * np.sin(angle)
            + axis * np.dot(axis, vector) * (1 - np.cos(angle)))


def make_tree_vessel(shape: TreeShape = TreeShape()) -> TreeVessel:
    """The tree's segments, radii and paths (deterministic: no randomness)."""
    root = np.zeros(3)
    up = np.array([0.0, 0.0, 1.0])
    segments: list[Points] = [_bezier(root, up, root + shape.root_length_mm * up)]
    radii = [shape.root_radius_mm]
    paths: list[tuple[int, ...]] = []
    # (segment index, end point, end direction, plane normal, level, path so far)
    stack: list[tuple[int, FloatArray, FloatArray, FloatArray, int, tuple[int, ...]]] = [
        (0, segments[0][-1], up, np.array([1.0, 0.0, 0.0]), 0, (0,))]
    angle = np.radians(shape.branch_deg)
    while stack:
        index, end, direction, normal, level, path = stack.pop()
        if level == shape.depth:
            paths.append(path)
            continue
        normal = _rotate(normal, direction, np.pi / 2)  # the next level branches in a plane a quarter turn on
        length = shape.root_length_mm * shape.length_ratio ** (level + 1)
        for sign in (1.0, -1.0):
            child = _rotate(direction, normal, sign * angle)
            points = _bezier(end, direction, end + length * child)
            segments.append(points)
            radii.append(shape.root_radius_mm * MURRAY_RATIO ** (level + 1))
            tangent = points[-1] - points[-2]
            stack.append((len(segments) - 1, points[-1], tangent / np.linalg.norm(tangent), normal, level + 1,
                          path + (len(segments) - 1,)))
    paths.sort()
    return TreeVessel(tuple(segments), tuple(radii), tuple(paths))


def tree_surface(tree: TreeVessel, triangles: int) -> tuple[FloatArray, IntArray]:
    """The union of every segment's capped tube, about ``triangles`` faces: vertices (V, 3) mm, faces (F, 3)."""
    import manifold3d as m3

    from softdesign.meshing.solids import checked, manifold_from_mesh
    from softdesign.samples.surfaces import framed_polyline, swept_tube

    area = sum(2 * np.pi * r * float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
               for p, r in zip(tree.segments, tree.radii, strict=True))
    edge = float(np.sqrt(area / (0.5 * triangles)))  # two triangles per edge x edge cell of the wall
    tubes = []
    for k, (points, radius) in enumerate(zip(tree.segments, tree.radii, strict=True)):
        # each child starts a little inside its parent (its first point backed off along its tangent), so the
        # union has no coincident faces at the junction
        step = points[1] - points[0]
        back = np.arange(int(np.ceil(0.5 * radius / np.linalg.norm(step))), 0, -1)[:, None]
        axis = np.concatenate([points[0] - back * step, points]) if k else points
        framed = framed_polyline(axis, f"tree segment {k}")
        rings = int(np.ceil(framed.length / edge)) + 1
        around = max(int(np.ceil(2 * np.pi * radius / edge)), 12)
        vertices, faces = swept_tube(framed, rings, around, np.full(2, radius), 0.0, np.zeros(2))
        tubes.append(manifold_from_mesh(vertices, faces, f"tree segment {k}")[0])
    mesh = checked(m3.Manifold.batch_boolean(tubes, m3.OpType.Add), "tree").to_mesh64()
    return np.asarray(mesh.vert_properties, float)[:, :3], np.asarray(mesh.tri_verts, np.int64)
