"""A surface in, VMTK-style centerlines out: one path from the shared inlet to each outlet.

The steps (each module says where it follows VMTK's ``vmtkcenterlines`` and
where it differs): check and close the surface (:mod:`.closing`), its
internal Voronoi diagram (:mod:`.voronoi`), the endpoints (:mod:`.endpoints`),
the least-cost paths (:mod:`.paths`), each continued straight to its
openings' centres (:mod:`.ends`), then smoothed.

No files, no printing: numpy and scipy only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from softdesign.centerline.closing import ClosedSurface, Opening, close_surface
from softdesign.centerline.endpoints import caps_from_regions, choose_inlet, graph_extremities, planar_caps
from softdesign.centerline.ends import EndTargets, reach_ends
from softdesign.centerline.paths import (
    bridge_components,
    check_path_length,
    least_cost_paths,
    seed_vertex,
    smooth_path,
    trim_rounded_ends,
)
from softdesign.centerline.voronoi import VoronoiGraph, internal_voronoi, mean_edge_length
from softdesign.errors import ConfigError, InputDataError
from softdesign.types import FloatArray, Points

#: RMS distance the smoothing spline keeps from the Voronoi path, as a fraction of the mean surface edge.
#: The path's zig-zag about the medial axis is a fraction of an edge; measured on the VMTK aorta, 0.1 of
#: an edge removes it and moves the curve by less than VMTK's own placement noise.
SMOOTHING_REL = 0.1
#: Arc-length spacing of the output points, as a fraction of the mean surface edge (VMTK's Voronoi path
#: has about one point per edge; half an edge keeps the spline's curvature).
SPACING_REL = 0.5
#: Most outlets a user may name.
MAX_OUTLETS = 64


@dataclass(frozen=True)
class CenterlineOptions:
    """Endpoints the user gives, and the face labels of the file (mm).

    Attributes
    ----------
    inlet : (3,) float or None -- the inlet is the opening (or cap) nearest this point; on a surface with
        neither, this point itself
    outlets : (3,) floats -- the outlets, in this order; default every opening or cap but the inlet; a point
        within an opening (nearer its centre than its radius) stands for the opening's centre
    regions : (F,) int or None -- one label per input face (ModelFaceID, CellEntityIds)
    """

    inlet: FloatArray | None = None
    outlets: tuple[FloatArray, ...] = ()
    regions: npt.NDArray[np.int64] | None = None


@dataclass(frozen=True)
class Centerlines:
    """Centerlines from one inlet, mm: ``paths[k]`` runs from the inlet to outlet k, proximal first.

    Attributes
    ----------
    paths : (n_k, 3) float per outlet
    radii : (n_k,) float per outlet -- maximum inscribed sphere radius at each point
    endpoints : how they were found: "openings", "face regions", "planar caps", "graph extremities", "given"
    inlet : (3,) float -- the inlet's centre (opening, cap or given point)
    outlets : (3,) float per outlet
    voronoi_vertices : how many internal Voronoi vertices the paths were searched among
    notes : what was done on the way
    continued_mm : (inlet, outlet) per path: how far each end was continued straight past the Voronoi
        diagram's last vertex to its opening's centre (or a rounded end's axis tip), mm
    short_mm : (inlet, outlet) per path: how far each end still is from its opening's centre, mm
        (0 when reached, or when the end has no opening)
    """

    paths: tuple[Points, ...]
    radii: tuple[FloatArray, ...]
    endpoints: str
    inlet: FloatArray
    outlets: tuple[FloatArray, ...]
    voronoi_vertices: int
    notes: tuple[str, ...] = field(default=())
    continued_mm: tuple[tuple[float, float], ...] = field(default=())
    short_mm: tuple[tuple[float, float], ...] = field(default=())


def extract_centerlines(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, options: CenterlineOptions = CenterlineOptions(),
    where: str = "surface",
) -> Centerlines:
    """Centerlines of a vessel surface, as VMTK's ``vmtkcenterlines`` computes them (see the package notes).

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    options : endpoints given by the user, face labels
    where : the file named in messages

    Raises
    ------
    InputDataError
        A surface that cannot be used (pieces, non-manifold, inconsistent winding, size), or that gives
        fewer than two endpoints.
    ConfigError
        Too many outlets given.
    GeometryError
        An outlet not connected to the inlet inside the surface.
    """
    if len(options.outlets) > MAX_OUTLETS:
        raise ConfigError(f"--outlet: {len(options.outlets)} outlets given, at most {MAX_OUTLETS}")
    closed = close_surface(vertices, faces, where)
    graph = internal_voronoi(closed.vertices, closed.faces)
    ends = _endpoints(closed, graph, options, where)
    kind, inlet, outlets, seeds = ends.kind, ends.inlet, ends.outlets, ends.seeds
    edge = mean_edge_length(closed.vertices, closed.faces)
    tree = cKDTree(closed.vertices)
    paths, radii, continued, short = [], [], [], []
    graph = bridge_components(graph, seeds)
    for k, ids in enumerate(least_cost_paths(graph, seeds[0], seeds[1:])):
        if kind == "graph extremities":
            ids = trim_rounded_ends(ids, graph)
        check_path_length(graph.points[ids], k)
        targets = _targets(ends, options, k)
        reached = reach_ends(graph.points[ids], graph.radius[ids], targets, (closed.vertices, closed.faces),
                             SPACING_REL * edge)
        points, radius = smooth_path(reached.points, tree, SPACING_REL * edge, SMOOTHING_REL * edge)
        paths.append(points)
        radii.append(hold_radius_on_runs(points, radius, reached.continued_mm))
        continued.append(reached.continued_mm)
        short.append(reached.short_mm)
    return Centerlines(tuple(paths), tuple(radii), kind, inlet, tuple(outlets), len(graph.points),
                       closed.notes + tuple(f"{where}: {line}" for line in ends.facts)
                       + tuple(f"warning: {where}: {line}" for line in ends.notes),
                       tuple(continued), tuple(short))


@dataclass(frozen=True)
class _Ends:
    """The endpoints found: how, where (mm), their Voronoi seeds (inlet first), which are openings' centres."""

    kind: str
    inlet: FloatArray
    outlets: list[FloatArray]
    seeds: list[int]
    notes: tuple[str, ...] = ()  # warnings
    centres: tuple[bool, ...] = ()  # inlet, then each outlet: an opening's (or cap's) centre, to be reached
    facts: tuple[str, ...] = ()  # notes that are no warning (the wall labels)


def _targets(ends: _Ends, options: CenterlineOptions, k: int) -> EndTargets:
    """What the ends of path ``k`` reach for: the openings' centres, or the axis tip of a rounded end."""
    if ends.kind == "graph extremities":
        return EndTargets(None, None, (options.inlet is None, True))
    inlet = ends.inlet if ends.centres[0] else None
    return EndTargets(inlet, ends.outlets[k] if ends.centres[k + 1] else None)


def hold_radius_on_runs(points: Points, radius: FloatArray, continued_mm: tuple[float, float]) -> FloatArray:
    """The radius (n,) with each straight continuation held at its value where the Voronoi path ends.

    Past the last Voronoi vertex the nearest surface point is the cap or the opening's rim, not the wall
    across the lumen, so the distance to it is no inscribed radius; the last inscribed sphere's is kept.
    """
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    start, stop = continued_mm[0], s[-1] - continued_mm[1]
    inside = (s >= start) & (s <= stop)
    if not inside.any():
        return radius
    held = radius.copy()
    held[s < start] = radius[np.flatnonzero(inside)[0]]
    held[s > stop] = radius[np.flatnonzero(inside)[-1]]
    return held


def _endpoints(closed: ClosedSurface, graph: VoronoiGraph, options: CenterlineOptions, where: str) -> _Ends:
    """How the endpoints were found, the inlet, the outlets, the Voronoi seed of each (inlet first), notes.

    A given outlet within an opening (nearer its centre than the opening's radius) is that opening's centre.
    """
    kind, candidates, notes, facts = _candidates(closed, graph, options)
    if len(candidates) == 0 and not options.outlets:
        ends = graph_extremities(graph)
        inlet_id = ends[0] if options.inlet is None else seed_vertex(graph, closed.vertices, options.inlet)
        ends = [e for e in ends if e != inlet_id] if options.inlet is None else ends[1:]
        points = [graph.points[e] for e in ends]
        return _Ends("graph extremities", graph.points[inlet_id], points, [inlet_id, *ends], notes, facts=facts)
    if candidates:
        first = choose_inlet(candidates, options.inlet)
        inlet, centres = candidates[first].centre, [True]
        given = [_opening_at(p, candidates) for p in options.outlets]
        outlets = [p if c is None else c.centre for p, c in zip(options.outlets, given, strict=True)] or [
            c.centre for k, c in enumerate(candidates) if k != first]
        centres += [c is not None for c in given] if options.outlets else [True] * len(outlets)
    elif options.inlet is not None:
        kind, inlet, outlets = "given", np.asarray(options.inlet, float), list(options.outlets)
        centres = [False] * (1 + len(outlets))
    else:
        raise InputDataError(
            f"{where}: --outlet given but no inlet: the surface has no openings or caps to choose it from; "
            "give --inlet x,y,z too"
        )
    if not outlets:
        raise InputDataError(
            f"{where}: only one endpoint found ({kind}); a centerline needs an inlet and at least one outlet - "
            "clip the vessel open at both ends, or give --inlet x,y,z and --outlet x,y,z"
        )
    seeds = [seed_vertex(graph, closed.vertices, point) for point in [inlet, *outlets]]
    return _Ends(kind if not options.outlets else "given", inlet, outlets, seeds, notes, tuple(centres), facts)


def _opening_at(point: FloatArray, openings: tuple[Opening, ...]) -> Opening | None:
    """The opening whose centre ``point`` (3,) mm lies within the radius of, or None."""
    point = np.asarray(point, float)
    nearest = min(openings, key=lambda o: float(np.linalg.norm(o.centre - point)))
    return nearest if float(np.linalg.norm(nearest.centre - point)) <= nearest.radius else None


def _candidates(
    closed: ClosedSurface, graph: VoronoiGraph, options: CenterlineOptions
) -> tuple[str, tuple[Opening, ...], tuple[str, ...], tuple[str, ...]]:
    """The openings, else the labelled caps, else the flat caps (empty when there are fewer than two); warnings;
    notes that are no warning.

    Labels that are not caps are ignored (the warnings say which and why, the wall labels once); when fewer
    than two labels are caps, the flat caps are looked for as on an unlabelled surface.
    """
    if closed.openings:
        return "openings", closed.openings, (), ()
    regions = options.regions
    notes: tuple[str, ...] = ()
    facts: tuple[str, ...] = ()
    if regions is not None and len(regions) == len(closed.faces) and len(np.unique(regions)) > 1:
        labelled, notes, walls = caps_from_regions(closed.vertices, closed.faces, regions, graph)
        facts = () if walls is None else (walls,)
        if len(labelled) >= 2:
            return "face regions", labelled, notes, facts
        notes += (f"fewer than two face labels are caps ({len(labelled)}); the endpoints are looked for as on an "
                  "unlabelled surface",)
    caps = planar_caps(closed.vertices, closed.faces)
    return ("planar caps", caps, notes, facts) if len(caps) >= 2 else ("graph extremities", (), notes, facts)


def points_from_user(values: list[tuple[float, float, float]], scale: float) -> tuple[Points, ...]:
    """User points (file units) as (3,) mm arrays."""
    return tuple(np.asarray(v, float) * scale for v in values)
