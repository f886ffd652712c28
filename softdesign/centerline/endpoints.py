"""Where the centerlines start and end, found without clicking.

VMTK asks the user to pick seed points (``-seedselector pickpoint``) or takes
the barycentres of the open profiles (``openprofiles``).  Here, in order:

1. an open surface: the centres of its boundary loops (:mod:`.closing`);
2. a capped surface whose file labels its faces (``ModelFaceID`` from
   SimVascular, ``CellEntityIds`` from VMTK's ``vmtkmeshgenerator``): the wall
   is the label of largest area, and every other label is a cap if it looks
   like one (:func:`caps_from_regions`: flat, disc-like, and as wide as the
   vessel it closes; SimVascular models label wall faces too), else it is
   ignored with a note saying why;
3. a capped surface without labels: flat, nearly planar, disc-like patches
   (a capper's flat ends), :func:`planar_caps`;
4. otherwise the ends of the Voronoi graph, :func:`graph_extremities`.

The inlet is the largest opening or cap unless the user names one.  VMTK has
no such rule (the user says which seed is the source); the largest opening is
the proximal end of every arterial tree the project's users bring (aorta,
carotid, coronary ostium), which is why it is the default.

No files, no printing: numpy and scipy only.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy import sparse
from scipy.sparse.csgraph import connected_components

from softdesign.centerline.closing import Opening
from softdesign.centerline.paths import farthest_vertex
from softdesign.centerline.voronoi import VoronoiGraph, mean_edge_length
from softdesign.types import FloatArray, IntArray

#: Neighbouring faces whose normals differ by less than this belong to one flat patch, degrees.  A wall
#: meshed at edge h on a radius R turns h / R radians between faces (about 10 degrees on the aorta);
#: a capper's flat end turns not at all.
PLANAR_DEG = 1.0
#: A flat patch is a cap when it has at least this many faces ...
MIN_CAP_FACES = 6
#: ... the radius of a disc of its area is at least this many mean edges (a few coplanar wall faces are not) ...
CAP_MIN_EDGES = 2.0
#: ... its area is at least this fraction of the disc spanning it (a strip along a straight wall is not) ...
DISC_FILL = 0.5
#: ... and its points stay within this fraction of its diameter from their best-fitting plane.
FLATNESS_REL = 0.01
#: A labelled face is a cap only if its points stay within this fraction of its diameter from their plane
#: (a capper's or SimVascular's cap is planar to rounding; a wall face of width w on a vessel of radius R
#: bows by w / (8 R) of its width, so only a sliver far narrower than the vessel passes) ...
LABEL_FLATNESS_REL = 0.02
#: ... and the radius of the disc of its area lies within these multiples of the widest inscribed sphere
#: touching it: a cap closes the vessel, so it is as wide as the lumen behind it (an elliptic end reaches
#: about 1.3); a wall face is much wider or much narrower than the lumen it lines.
LABEL_RADIUS_RANGE = (0.5, 1.5)
#: The reason a labelled face is refused when it bends: a wall face, not a cap (said once for all of them).
NOT_PLANAR = "not planar"
#: Most wall labels the note lists by number.
MAX_LISTED_LABELS = 12
#: A side branch found by farthest-point sweeps must reach this many radii beyond the paths so far.
BRANCH_MIN_RADII = 3.0
#: How far behind a graph extremity its width is measured, as a fraction of the graph's longest path.
WIDTH_REACH = 0.1
#: Most extremities the sweeps look for (a vessel tree of more branches should be clipped open or capped).
MAX_EXTREMITIES = 16


def choose_inlet(openings: tuple[Opening, ...], inlet: FloatArray | None) -> int:
    """Index of the inlet: the opening nearest ``inlet`` (3,) mm when given, else the one of largest area."""
    if inlet is not None:
        return int(np.argmin([np.linalg.norm(o.centre - inlet) for o in openings]))
    return int(np.argmax([o.area for o in openings]))


def caps_from_regions(
    vertices: FloatArray, faces: IntArray, regions: npt.ArrayLike, graph: VoronoiGraph
) -> tuple[tuple[Opening, ...], tuple[str, ...], str | None]:
    """Caps of a labelled surface, by label order; a warning for each label refused as a cap; the wall labels.

    The label of largest area is the wall.  Every other label is a cap only if it is planar (within
    LABEL_FLATNESS_REL of its diameter), disc-like (DISC_FILL of the disc spanning it) and as wide as the
    vessel it closes (LABEL_RADIUS_RANGE of the widest inscribed sphere touching it).  A label that is not
    planar bends with the vessel: it is a wall face, as SimVascular labels them, which is expected, so all
    of them are said once ("N face labels are walls, not openings", the third value, None when there are
    none).  A planar label refused for another reason may be a cap that was missed: its warning names it,
    its area and the reason.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    regions : (F,) int -- one label per face (ModelFaceID, CellEntityIds)
    graph : the surface's internal Voronoi diagram (the inscribed spheres the labels are measured against)
    """
    regions = np.asarray(regions).reshape(-1)
    areas = _face_areas(vertices, faces)
    labels = np.unique(regions)
    totals = np.array([areas[regions == label].sum() for label in labels])
    wall = labels[int(np.argmax(totals))]
    caps, notes, walls = [], [], []
    for label in labels[labels != wall]:
        chosen = regions == label
        reason = label_not_a_cap(vertices, faces[chosen], float(areas[chosen].sum()), graph)
        if reason is None:
            caps.append(_patch_opening(vertices, faces[chosen], areas[chosen]))
        elif reason.startswith(NOT_PLANAR):
            walls.append(int(label))
        else:
            notes.append(f"face label {int(label)} ({float(areas[chosen].sum()):.3g} mm^2) is not taken as an "
                         f"opening: {reason}")
    return tuple(caps), tuple(notes), _walls_note(walls)


def _walls_note(walls: list[int]) -> str | None:
    """'3 face labels are walls, not openings (labels 4, 5, 9: ...)', or None without such labels."""
    if not walls:
        return None
    head = "1 face label is a wall, not an opening" if len(walls) == 1 else (
        f"{len(walls)} face labels are walls, not openings")
    listed = ", ".join(map(str, walls[:MAX_LISTED_LABELS])) + (", ..." if len(walls) > MAX_LISTED_LABELS else "")
    return (f"{head} (label{'s' if len(walls) > 1 else ''} {listed}: {NOT_PLANAR}, they bend with the vessel "
            f"by more than {100 * LABEL_FLATNESS_REL:.0f} % of their width, as a cap does not)")


def label_not_a_cap(vertices: FloatArray, faces: IntArray, area: float, graph: VoronoiGraph) -> str | None:
    """Why the labelled patch ``faces`` (k, 3) of ``area`` mm^2 is not a cap, or None when it is one."""
    ids = np.unique(faces)
    points = vertices[ids]
    centred = points - points.mean(axis=0)
    diameter = 2.0 * float(np.linalg.norm(centred, axis=1).max())
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    bow = float(np.abs(centred @ normal).max())
    if bow > LABEL_FLATNESS_REL * diameter:
        return (f"{NOT_PLANAR} (its points leave their plane by {bow:.3g} mm, {100 * bow / diameter:.3g} % of its "
                f"{diameter:.3g} mm width; a cap stays within {100 * LABEL_FLATNESS_REL:.0f} %)")
    if area < DISC_FILL * np.pi * (diameter / 2.0) ** 2:
        return (f"not disc-like (it covers {100 * area / (np.pi * diameter**2 / 4):.0f} % of the disc spanning it, "
                f"a cap at least {100 * DISC_FILL:.0f} %)")
    touching = np.isin(graph.tets, ids).any(axis=1)
    if not touching.any():
        return "no inscribed sphere touches it"
    lumen = float(graph.radius[touching].max())
    radius = float(np.sqrt(area / np.pi))
    low, high = LABEL_RADIUS_RANGE
    if not low * lumen <= radius <= high * lumen:
        return (f"{'wider' if radius > high * lumen else 'narrower'} than the vessel it would close (a disc of "
                f"radius {radius:.2f} mm against the {lumen:.2f} mm inscribed sphere touching it; a cap is "
                f"{low:g} to {high:g} times it)")
    return None


def planar_caps(vertices: FloatArray, faces: IntArray) -> tuple[Opening, ...]:
    """Flat, disc-like patches of a closed surface (see the module constants), in the order of their first face."""
    normals = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    areas = 0.5 * np.linalg.norm(normals, axis=1)
    normals = normals / np.where(areas > 0.0, 2.0 * areas, 1.0)[:, None]
    a, b = _face_pairs(faces)
    flat = np.einsum("ij,ij->i", normals[a], normals[b]) > np.cos(np.radians(PLANAR_DEG))
    graph = sparse.csr_array((np.ones(int(flat.sum())), (a[flat], b[flat])), shape=(len(faces), len(faces)))
    _, label = connected_components(graph, directed=False)
    sizes = np.bincount(label)
    patch_areas = np.bincount(label, weights=areas)
    min_area = np.pi * (CAP_MIN_EDGES * mean_edge_length(vertices, faces)) ** 2
    caps = []
    for patch in np.flatnonzero((sizes >= MIN_CAP_FACES) & (patch_areas >= min_area)):
        chosen = label == patch
        if _disc_like(vertices[np.unique(faces[chosen])], float(areas[chosen].sum())):
            caps.append((int(np.argmax(chosen)), _patch_opening(vertices, faces[chosen], areas[chosen])))
    return tuple(opening for _, opening in sorted(caps, key=lambda item: item[0]))


def graph_extremities(graph: VoronoiGraph) -> list[int]:
    """Voronoi vertex ids of the graph's ends: the widest end first, then the others by farthest-point sweeps.

    An end's width is the largest inscribed radius within WIDTH_REACH of the longest path's length of it
    (the tip of a rounded end has a vanishing radius; the vessel behind it does not).

    The first two are the ends of the graph's longest shortest path (a double sweep from vertex 0); every
    next one is the vertex farthest from the paths so far, kept while it lies BRANCH_MIN_RADII radii
    beyond them.
    """
    first, _ = farthest_vertex(graph, [0])
    second, length = farthest_vertex(graph, [first])
    ends = [first, second]
    from softdesign.centerline.paths import least_cost_paths

    reached = np.unique(np.concatenate(least_cost_paths(graph, first, [second])))
    while len(ends) < MAX_EXTREMITIES:
        far, distance = farthest_vertex(graph, reached)
        if distance < BRANCH_MIN_RADII * float(np.median(graph.radius[reached])):
            break
        ends.append(far)
        reached = np.unique(np.concatenate([reached, *least_cost_paths(graph, first, [far])]))
    widest = int(np.argmax([_radius_near(graph, end, WIDTH_REACH * length) for end in ends]))
    return [ends[widest], *ends[:widest], *ends[widest + 1:]]


def _radius_near(graph: VoronoiGraph, vertex: int, reach_mm: float) -> float:
    """The largest inscribed radius within ``reach_mm`` (along the graph) of ``vertex``, mm."""
    from scipy.sparse.csgraph import dijkstra

    lengths = np.linalg.norm(graph.points[graph.edges[:, 0]] - graph.points[graph.edges[:, 1]], axis=1)
    distance = dijkstra(graph.adjacency(np.maximum(lengths, 1e-12)), indices=np.array([vertex]), limit=reach_mm)
    return float(graph.radius[np.isfinite(distance[0])].max())


def _face_areas(vertices: FloatArray, faces: IntArray) -> FloatArray:
    corners = vertices[faces]
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def _face_pairs(faces: IntArray) -> tuple[IntArray, IntArray]:
    """Pairs of faces sharing an edge (each pair once)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(faces)), 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    edges, owner = edges[order], owner[order]
    same = np.all(edges[1:] == edges[:-1], axis=1)
    return owner[:-1][same], owner[1:][same]


def _disc_like(points: FloatArray, area: float) -> bool:
    centred = points - points.mean(axis=0)
    diameter = 2.0 * float(np.linalg.norm(centred, axis=1).max())
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    flat = float(np.abs(centred @ normal).max()) <= FLATNESS_REL * diameter
    return flat and area >= DISC_FILL * np.pi * (diameter / 2.0) ** 2


def _patch_opening(vertices: FloatArray, faces: IntArray, areas: FloatArray) -> Opening:
    """An opening for a patch of faces: its area-weighted centroid and its area."""
    centroids = vertices[faces].mean(axis=1)
    return Opening(centroids.T @ areas / areas.sum(), float(areas.sum()))
