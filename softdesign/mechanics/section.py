"""One section of the actuator under chamber pressures: its deformed centerline, best arc, chamber lengths, stress.

A section's mesh (:class:`SectionMesh`) is the unloaded body as cast, with its
base face's nodes fixed and each chamber's wall triangles named.  The solve
(:func:`simulate_section`) is in quadratic tetrahedra made from it
(:mod:`softdesign.mechanics.quadratic`: a wall one element thick bends, and
the curvature converges under refinement) and gives the displacement; from it:

- the deformed centerline: the reference centerline's points carried by the
  displacement interpolated (quadratically) in the element that holds each one;
- the best arc through it (:func:`softdesign.kinematics.pcc_fit.fit_arc`, in the
  section's base frame: z along the centerline's tangent, x along N, y along
  B) and how far it misses (max and RMS over the centerline's points, mm);
- each chamber's length: the polyline through the centroids of its wall nodes,
  level by level along the reference centerline's arc length;
- the largest principal stretch and the largest principal Cauchy stress at any
  quadrature point, and in which element.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw, cauchy_stress
from softdesign.errors import MeshError, SolveError
from softdesign.kinematics.pcc_fit import arc_points, fit_arc, trapezoid_weights
from softdesign.mechanics.continuation import ContinuationSettings, follow_pressures
from softdesign.mechanics.linear_solve import TangentSolver
from softdesign.mechanics.load_steps import stepped_from_rest
from softdesign.mechanics.newton import NewtonSettings, PressureProblem, SolveRecord, solve_pressures
from softdesign.mechanics.quadratic import (
    QuadraticMesh,
    curved_barycentric,
    quadratic_faces,
    quadratic_fixed,
    quadratic_mesh,
    quadratic_state,
    shape_values,
)
from softdesign.mechanics.reinforcement import FibreMembrane, HoopThread, hoop_membrane
from softdesign.mechanics.tets import TetMesh, make_tet_mesh
from softdesign.types import FloatArray, IntArray

#: A centerline point counts as inside an element when its barycentric coordinates are all above this.
INSIDE_TOL = -1e-9
#: Node levels along the centerline are the same when their arc lengths differ by less than this, mm.
LEVEL_TOL_MM = 1e-6


@dataclass(frozen=True)
class SectionMesh:
    """A section's reference mesh and named sets, in the section's base frame (mm).

    Attributes
    ----------
    points : (V, 3) float, mm, in the base frame (base centre at the origin, centerline tangent +z)
    tets : (E, 4) int, positively oriented
    base : (V,) bool, nodes of the base face (fixed)
    wall_faces : (F, 3) int, chamber walls, normals out of the chamber into the material
    face_chamber : (F,) int, the chamber (0 .. k-1) of each wall face
    centerline : (n, 3) float, mm, the reference centerline from base to tip, inside the material
    node_l : (V,) float, mm, each node's arc length along the centerline (its level)
    chamber_angles : (k,) float, rad, each chamber's angle from x towards y
    chamber_radii_mm : (k,) float, mm, each chamber's radius (the reinforcement's winding needs it), or None
    feed_faces : (G, 3) int or None, the walls and end lids of the feeds that cross the section (cavities of
        their distal chambers' pressures), normals out of the feed
    face_feed : (G,) int or None, the feed (0 .. m-1) of each feed face
    feed_radii_mm : (m,) float or None, each feed's radius, mm
    curved_edges : (K, 2) int or None, edges (corner pairs) whose quadratic midside nodes are off their middles
        (:mod:`softdesign.mechanics.curved_walls`); None: every edge straight
    curved_midpoints : (K, 3) float or None, mm, those midside nodes' positions
    """

    points: FloatArray
    tets: IntArray
    base: np.ndarray
    wall_faces: IntArray
    face_chamber: IntArray
    centerline: FloatArray
    node_l: FloatArray
    chamber_angles: FloatArray
    chamber_radii_mm: FloatArray | None = None
    feed_faces: IntArray | None = None
    face_feed: IntArray | None = None
    feed_radii_mm: FloatArray | None = None
    curved_edges: IntArray | None = None
    curved_midpoints: FloatArray | None = None

    @property
    def chamber_count(self) -> int:
        """How many chambers (pressures) the section takes."""
        return len(self.chamber_angles)

    @property
    def feed_count(self) -> int:
        """How many feeds of distal chambers cross the section as cavities (0: none, or meshed solid)."""
        return 0 if self.feed_radii_mm is None else len(self.feed_radii_mm)


@dataclass(frozen=True)
class SectionResult:
    """What one forward solve gives (mm, rad, kPa)."""

    pressures_kpa: FloatArray  #: (k,) the chamber pressures
    centerline: FloatArray  #: (n, 3) the deformed centerline, base frame
    kappa: float  #: best arc's curvature, 1/mm
    phi: float  #: best arc's bending-plane angle, rad (towards the centre of curvature)
    length: float  #: best arc's length, mm
    arc_max_mm: float  #: largest distance between the centerline and its arc
    arc_rms_mm: float  #: arc-length RMS of that distance
    chamber_lengths: FloatArray  #: (k,) deformed chamber lengths, mm
    rest_chamber_lengths: FloatArray  #: (k,) the same unloaded, mm
    max_stretch: float  #: largest principal stretch of any element
    max_stress_kpa: float  #: largest principal Cauchy stress of any element, kPa
    max_stress_at: FloatArray  #: (3,) reference centroid of that element, mm
    record: SolveRecord  #: load steps, iterations and residuals
    displacement: FloatArray | None = None  #: (N, 3) mm, every node's (corners first), when kept


def check_section(section: SectionMesh) -> TetMesh:
    """The reference mesh of a section, its named sets checked (MeshError naming what is wrong)."""
    mesh = make_tet_mesh(section.points, section.tets)
    V = len(mesh.points)
    if section.base.shape != (V,) or not section.base.any():
        raise MeshError(f"section mesh: the base node set must be (V,) = ({V},) and not empty")
    faces, chambers = np.asarray(section.wall_faces), np.asarray(section.face_chamber)
    if faces.ndim != 2 or faces.shape[1] != 3 or chambers.shape != (len(faces),):
        raise MeshError(f"section mesh: wall faces (F, 3) with one chamber each; got {faces.shape}, {chambers.shape}")
    missing = sorted(set(range(section.chamber_count)) - set(chambers.tolist()))
    if missing or (len(chambers) and chambers.max() >= section.chamber_count):
        raise MeshError(f"section mesh: every chamber needs wall faces; chambers without any: {missing}")
    if section.node_l.shape != (V,) or section.centerline.ndim != 2 or len(section.centerline) < 3:
        raise MeshError("section mesh: node_l must be (V,) and the centerline (n >= 3, 3)")
    return mesh


def section_problem(section: SectionMesh, law: HyperelasticLaw, thread: HoopThread | None = None
                    ) -> PressureProblem:
    """The pressure problem of a section in quadratic tetrahedra (:mod:`softdesign.mechanics.quadratic`).

    The section's linear tetrahedra get a node at each edge's middle; the base
    nodes (corners and the midpoints between them) are fixed in every
    direction and each chamber's wall carries its pressure on 6-node faces.
    With a ``thread``, every chamber's side wall carries the hoop winding's fibres
    (:mod:`softdesign.mechanics.reinforcement`), its axis the centerline's tangent at the face's level; so does
    every feed's (the feed's core wound as the chambers', a feed that does not swell).  The feeds crossing the
    section (``feed_faces``) are cavities after the chambers: the problem takes k + m pressures.
    """
    mesh = quadratic_mesh(check_section(section), section.curved_edges, section.curved_midpoints)
    fixed = quadratic_fixed(mesh, np.repeat(section.base[:, None], 3, axis=1)).ravel()
    walls, chambers = np.asarray(section.wall_faces, np.int64), np.asarray(section.face_chamber, np.int64)
    if section.feed_count:  # the feeds are cavities k .. k + m - 1
        walls = np.concatenate([walls, np.asarray(section.feed_faces, np.int64)])
        chambers = np.concatenate([chambers, section.chamber_count + np.asarray(section.face_feed, np.int64)])
    faces = quadratic_faces(mesh, walls)
    fibres = None if thread is None else _wall_fibres(section, mesh, faces, chambers, thread, law)
    return PressureProblem(mesh, law, fixed, faces, chambers, fibres)


def _wall_fibres(section: SectionMesh, mesh: QuadraticMesh, faces: IntArray, chambers: IntArray,
                 thread: HoopThread, law: HyperelasticLaw) -> FibreMembrane:
    """The hoop thread on every chamber wall face, its axis the centerline's tangent at the face's mean level."""
    if section.chamber_radii_mm is None:
        raise MeshError("section mesh: a reinforced section needs each chamber's radius (chamber_radii_mm)")
    line = section.centerline
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))])
    tangents = np.gradient(line, s, axis=0)
    level = section.node_l[faces[:, :3]].mean(axis=1)
    axes = np.stack([np.interp(level, s, tangents[:, k]) for k in range(3)], axis=1)
    radii = np.concatenate([np.asarray(section.chamber_radii_mm, float),
                            np.zeros(0) if section.feed_radii_mm is None else section.feed_radii_mm])[chambers]
    return hoop_membrane(mesh.points, faces, axes, radii, thread, 3.0 * law.mu_kpa)  # incompressible: E = 3 mu


def locate(mesh: TetMesh, query: FloatArray) -> tuple[IntArray, FloatArray]:
    """The element (n,) holding each reference point of ``query`` (n, 3) and its barycentric weights (n, 4).

    Raises
    ------
    MeshError
        A point lies in no element (outside the material).
    """
    corners = mesh.points[mesh.tets]
    inverse = np.linalg.inv((corners[:, 1:] - corners[:, :1]).transpose(0, 2, 1))  # (E, 3, 3)
    local = np.einsum("eij,nej->nei", inverse, query[:, None, :] - corners[None, :, 0, :])  # (n, E, 3)
    bary = np.concatenate([1.0 - local.sum(axis=2, keepdims=True), local], axis=2)
    worst = bary.min(axis=2)  # (n, E)
    element = np.argmax(worst, axis=1)
    if np.any(worst[np.arange(len(query)), element] < INSIDE_TOL):
        bad = int(np.argmin(worst.max(axis=1)))
        raise MeshError(f"section mesh: centerline point {bad} at {np.round(query[bad], 3).tolist()} mm is in no "
                        "element; the centerline must run through the material")
    return element, bary[np.arange(len(query)), element]


def chamber_lengths(section: SectionMesh, positions: FloatArray) -> FloatArray:
    """Each chamber's length (k,), mm: the polyline through its wall nodes' centroids, level by level."""
    lengths = np.zeros(section.chamber_count)
    for c in range(section.chamber_count):
        nodes = np.unique(section.wall_faces[section.face_chamber == c])
        levels = np.round(section.node_l[nodes] / LEVEL_TOL_MM).astype(np.int64)
        _, which = np.unique(levels, return_inverse=True)
        counts = np.bincount(which)
        centroids = np.stack([np.bincount(which, positions[nodes, k]) / counts for k in range(3)], axis=1)
        lengths[c] = np.linalg.norm(np.diff(centroids, axis=0), axis=1).sum()
    return lengths


def arc_of(centerline: FloatArray, fractions: FloatArray) -> tuple[float, float, float, float, float]:
    """Best arc (kappa 1/mm, phi rad, L mm) through ``centerline`` (n, 3) mm and its misfit (max, RMS) mm."""
    length = float(np.linalg.norm(np.diff(centerline, axis=0), axis=1).sum())
    arc = fit_arc(centerline - centerline[0], fractions, length)
    miss = np.linalg.norm(arc_points(arc.kappa, arc.phi, arc.length, fractions) - (centerline - centerline[0]), axis=1)
    rms = float(np.sqrt(trapezoid_weights(fractions) @ miss**2))
    return arc.kappa, arc.phi, arc.length, float(miss.max()), rms


def _stress_figures(problem: PressureProblem, u: FloatArray) -> tuple[float, float, FloatArray]:
    """Largest principal stretch and Cauchy stress (kPa) over the quadrature points, and that element's centroid."""
    mesh = problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    state = quadratic_state(mesh, problem.law, u)
    E, Q = state.J.shape
    F = state.F.reshape(E * Q, 3, 3)
    stretch = np.sqrt(np.linalg.eigvalsh(np.einsum("eki,ekj->eij", F, F))[:, -1])
    sigma = cauchy_stress(problem.law, F, np.repeat(state.pressure, Q))
    principal = np.linalg.eigvalsh(sigma)[:, -1]
    worst = int(np.argmax(principal)) // Q
    at = mesh.linear.points[mesh.linear.tets[worst]].mean(axis=0)
    return float(stretch.max()), float(principal.max()), at


@dataclass(frozen=True)
class PreparedSection:
    """A section ready to solve: its problem, where its centerline's points lie, their arc-length fractions."""

    section: SectionMesh
    problem: PressureProblem
    elements: IntArray  #: (n,) the element holding each centerline point
    weights: FloatArray  #: (n, 4) their barycentric weights
    fractions: FloatArray  #: (n,) arc-length fraction of each centerline point, 0 to 1
    solver: TangentSolver = field(default_factory=TangentSolver)  #: keeps the order of its Newton matrices

    def centerline_motion(self, u: FloatArray) -> FloatArray:
        """The displacement (n, 3) mm of the centerline's points under nodal ``u`` (N, 3) mm (the elements' shapes)."""
        mesh = self.problem.mesh
        assert isinstance(mesh, QuadraticMesh)
        return np.einsum("na,nai->ni", shape_values(self.weights), u[mesh.cells[self.elements]])

    def carried_centerline(self, u: FloatArray) -> FloatArray:
        """The centerline (n, 3) mm carried by the displacement ``u`` (N, 3) mm."""
        return self.section.centerline + self.centerline_motion(u)


def prepare_section(section: SectionMesh, law: HyperelasticLaw, thread: HoopThread | None = None
                    ) -> PreparedSection:
    """Check a section and locate its centerline (MeshError when either is wrong); ``thread``: its reinforcement."""
    problem = section_problem(section, law, thread)
    assert isinstance(problem.mesh, QuadraticMesh)
    elements, weights = locate(problem.mesh.linear, section.centerline)
    # the centerline's points where curved elements' maps put them (a straight mesh's as located)
    weights = curved_barycentric(problem.mesh, elements, weights, section.centerline)
    steps = np.linalg.norm(np.diff(section.centerline, axis=0), axis=1)
    fractions = np.concatenate([[0.0], np.cumsum(steps)]) / steps.sum()
    return PreparedSection(section, problem, elements, weights, fractions)


def measure_section(prepared: PreparedSection, u: FloatArray, pressures: FloatArray,
                    record: SolveRecord) -> SectionResult:
    """The figures of an equilibrium ``u`` (V, 3) mm at ``pressures`` (k,) kPa."""
    centerline = prepared.carried_centerline(u)
    kappa, phi, length, arc_max, arc_rms = arc_of(centerline, prepared.fractions)
    stretch, stress, at = _stress_figures(prepared.problem, u)
    section = prepared.section
    corners = section.points + u[:len(section.points)]
    return SectionResult(np.asarray(pressures, float), centerline, kappa, phi, length, arc_max, arc_rms,
                         chamber_lengths(section, corners), chamber_lengths(section, section.points),
                         stretch, stress, at, record, u)


def simulate_section(section: SectionMesh, law: HyperelasticLaw, pressures: FloatArray,
                     settings: NewtonSettings, thread: HoopThread | None = None,
                     feed_pressures: FloatArray | None = None) -> SectionResult:
    """Solve the section at chamber ``pressures`` (k,) kPa and measure it (see the module's docstring).

    ``feed_pressures`` (m,) kPa: those of the feeds that cross the section as cavities (their distal chambers'
    pressures; None: 0).

    Raises
    ------
    MeshError
        Bad named sets, or a centerline outside the material.
    SolveError
        The pressures lie beyond a limit point, or the solve stopped: the message gives the largest
        pressures reached (:mod:`softdesign.mechanics.continuation`).
    """
    pressures = np.asarray(pressures, float)
    if pressures.shape != (section.chamber_count,):
        raise ValueError(f"expected {section.chamber_count} pressures, got shape {pressures.shape}")
    feeds = np.zeros(section.feed_count) if feed_pressures is None else np.asarray(feed_pressures, float)
    if feeds.shape != (section.feed_count,):
        raise ValueError(f"expected {section.feed_count} feed pressures, got shape {feeds.shape}")
    prepared = prepare_section(section, law, thread)
    every = np.concatenate([pressures, feeds])  # the chambers', then the feeds'
    if thread is not None:
        # Reinforced: the thread holds the chambers' radius, so there is no limit point to find, and their volume
        # barely grows with pressure, which makes volume control ill-conditioned (with kevlar it stopped at 0.3 kPa
        # of 10 on the demo's section, and stepped past the asked pressure on the whole device); load steps from
        # zero reach it, as the simulate stage's search does, the first step and the path as the whole device's.
        stepped = stepped_from_rest(settings, float(np.max(np.abs(every), initial=0.0)), law.mu_kpa)
        u, record = solve_pressures(prepared.problem, every, stepped, solver=prepared.solver)
        return measure_section(prepared, u, pressures, record)
    path = follow_pressures(prepared.problem, every, ContinuationSettings(
        first_step=1.0 / settings.load_steps, max_cutbacks=settings.max_cutbacks, newton=settings),
        solver=prepared.solver)
    if path.status != "reached":
        raise SolveError(path.stopped_because(every))
    return measure_section(prepared, path.end.u, pressures, path.record())
