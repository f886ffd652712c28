"""The whole device in one finite-element solve: every section's mesh in one frame, tied at the joints.

Why sections tied, not one swept mesh
    The swept mesher (:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) cuts every hole
    out of one cross-section, so two sections whose chambers overlap in the
    cross-section (a single-supply device puts each section's chamber
    wherever its bend asks) cannot share one.  Each section is meshed on its
    own (:mod:`softdesign.mechanics.layout_section`: the same swept mesher on
    the section's own cross-section), all are placed in the device's frame
    (mm), and consecutive sections are tied at their joint
    (:mod:`softdesign.mechanics.device_ties`).  The joint faces of two
    sections lie in one plane (both end layers are the body's normal
    section there, with the same skin polygon), so a tie starts with no gap.
Loads and supports
    Section 1's base is clamped; every chamber (and every feed crossing a
    section) carries its pressure as a follower load on its deformed walls;
    the hoop thread, when given, lines every chamber's (and feed's) side wall
    (:mod:`softdesign.mechanics.reinforcement`).  The pressures grow in load
    steps (:func:`solve_device` says why not in volume steps); a stop names the
    largest load reached.
Assumptions
    As one section's (:mod:`softdesign.mechanics.section`): quasi-static, no
    gravity, no contact with the vessel, the silicone's hyperelastic law, the
    thread bonded to the wall; and the joints' ties are stiff springs (a
    penalty): the largest gap they leave at equilibrium is reported.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import MeshError, SolveError
from softdesign.mechanics.backbone import backbone_fibres
from softdesign.mechanics.device_ties import Ties, joint_faces, tie_joints
from softdesign.mechanics.embedded_thread import thread_fibres
from softdesign.mechanics.linear_solve import TangentSolver
from softdesign.mechanics.load_steps import stepped_from_rest
from softdesign.mechanics.newton import NewtonSettings, PressureProblem, SolveRecord, SolveStopped, solve_pressures
from softdesign.mechanics.quadratic import QuadraticMesh, curved_barycentric, shape_values
from softdesign.mechanics.reinforcement import HoopThread
from softdesign.mechanics.section import SectionMesh, locate, section_problem
from softdesign.mechanics.tets import make_tet_mesh
from softdesign.types import FloatArray, IntArray

#: The threads' rounding floor on the residual over its estimate (:func:`roundoff_floor_mn`): a safety factor.
FIBRE_ROUNDOFF = 10.0
#: Centerline points located per batch (each batch holds an (n, E, 4) array of barycentric coordinates).
LOCATE_BATCH = 16


@dataclass(frozen=True)
class DevicePart:
    """One section's mesh in the device's frame, with where it starts and its centerline samples.

    Attributes
    ----------
    mesh : the section's mesh, points and centerline in the device's frame (mm)
    base_frame : (3, 3) float, columns (N, B, T) of the body's frame at the section's base, unloaded
    tip_frame : (3, 3) float, the same at its tip
    samples : (n, 3) float, mm, points of the section's unloaded centerline, base to tip (measured)
    feed_chambers : (m,) int, the chamber (numbered over the whole device, base first) that each feed crossing
        the section feeds: the feed carries that chamber's pressure
    notes : what the section's mesh leaves out of the design (a taper meshed as a cylinder), for the answer
    """

    mesh: SectionMesh
    base_frame: FloatArray
    tip_frame: FloatArray
    samples: FloatArray
    feed_chambers: IntArray = field(default_factory=lambda: np.zeros(0, np.int64))
    notes: tuple[str, ...] = ()


def placed_section(section: SectionMesh, origin: FloatArray, frame: FloatArray) -> SectionMesh:
    """``section`` (in its base frame) carried into the device's frame: ``x = origin + frame @ x_local``.

    ``origin`` (3,) mm, ``frame`` (3, 3) columns (N, B, T) of the section's base frame in the device's frame.
    """
    origin, frame = np.asarray(origin, float), np.asarray(frame, float)
    curved = None if section.curved_midpoints is None else origin + section.curved_midpoints @ frame.T
    return replace(section, points=origin + section.points @ frame.T,
                   centerline=origin + section.centerline @ frame.T, curved_midpoints=curved)


@dataclass(frozen=True)
class DeviceMesh:
    """Every section's mesh as one :class:`SectionMesh` (section 1's base fixed), and where each part lies.

    Attributes
    ----------
    whole : the sections' meshes concatenated (nodes, elements, chambers, feeds in section order)
    parts : the sections
    node_start : (n + 1,) int, section i's corner nodes are ``node_start[i]:node_start[i + 1]``
    tet_start : (n + 1,) int, its elements likewise
    chamber_start : (n + 1,) int, its chambers likewise (the pressures' order)
    feed_start : (n + 1,) int, the feeds crossing it likewise (after every chamber in the pressures)
    """

    whole: SectionMesh
    parts: tuple[DevicePart, ...]
    node_start: IntArray
    tet_start: IntArray
    chamber_start: IntArray
    feed_start: IntArray

    @property
    def chamber_count(self) -> int:
        """Chambers of the whole device."""
        return int(self.chamber_start[-1])

    @property
    def feed_count(self) -> int:
        """Feeds meshed as cavities, over every section."""
        return int(self.feed_start[-1])

    @property
    def feed_chambers(self) -> IntArray:
        """(m,) the chamber each feed (over every section) feeds."""
        return np.concatenate([np.asarray(p.feed_chambers, np.int64) for p in self.parts])

    def section_of_node(self, node: int) -> int:
        """The section (0 at the base) of corner node ``node``."""
        return int(np.searchsorted(self.node_start, node, side="right") - 1)

    def section_of_element(self, element: int) -> int:
        """The section (0 at the base) of element ``element``."""
        return int(np.searchsorted(self.tet_start, element, side="right") - 1)


def _starts(counts: Sequence[int]) -> IntArray:
    return np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)


def assemble_device(parts: Sequence[DevicePart]) -> DeviceMesh:
    """The sections as one mesh (MeshError when there are none, or a part's named sets are wrong)."""
    if not parts:
        raise MeshError("device mesh: no sections")
    meshes = [p.mesh for p in parts]
    nodes = _starts([len(m.points) for m in meshes])
    tets = _starts([len(m.tets) for m in meshes])
    chambers = _starts([m.chamber_count for m in meshes])
    feeds = _starts([m.feed_count for m in meshes])
    offsets = np.concatenate([[0.0], np.cumsum([_length(m.centerline) for m in meshes])])
    feed_faces = [m.feed_faces + nodes[i] for i, m in enumerate(meshes) if m.feed_count]
    whole = SectionMesh(
        points=np.concatenate([m.points for m in meshes]),
        tets=np.concatenate([m.tets + nodes[i] for i, m in enumerate(meshes)]),
        base=np.concatenate([m.base if i == 0 else np.zeros(len(m.points), bool) for i, m in enumerate(meshes)]),
        wall_faces=np.concatenate([m.wall_faces + nodes[i] for i, m in enumerate(meshes)]),
        face_chamber=np.concatenate([m.face_chamber + chambers[i] for i, m in enumerate(meshes)]),
        # each later section's first point is the one before's last: dropped (the tangents need distinct points)
        centerline=np.concatenate([m.centerline if i == 0 else m.centerline[1:] for i, m in enumerate(meshes)]),
        node_l=np.concatenate([m.node_l + offsets[i] for i, m in enumerate(meshes)]),
        chamber_angles=np.concatenate([m.chamber_angles for m in meshes]),
        chamber_radii_mm=None if any(m.chamber_radii_mm is None for m in meshes) else np.concatenate(
            [np.asarray(m.chamber_radii_mm, float) for m in meshes]),
        feed_faces=np.concatenate(feed_faces) if feed_faces else None,
        face_feed=np.concatenate([m.face_feed + feeds[i] for i, m in enumerate(meshes) if m.feed_count])
        if feed_faces else None,
        feed_radii_mm=np.concatenate([m.feed_radii_mm for m in meshes if m.feed_count]) if feed_faces else None,
        **_curved_parts(meshes, nodes),
    )
    return DeviceMesh(whole, tuple(parts), nodes, tets, chambers, feeds)


def _curved_parts(meshes: Sequence[SectionMesh], nodes: IntArray) -> dict[str, np.ndarray | None]:
    """The sections' curved chamber-wall edges (their corners numbered in the whole mesh) and their midside nodes'
    positions (:mod:`softdesign.mechanics.curved_walls`), or None for both when every edge is straight."""
    edges = [m.curved_edges + nodes[i] for i, m in enumerate(meshes) if m.curved_edges is not None]
    if not edges:
        return {"curved_edges": None, "curved_midpoints": None}
    midpoints = [np.asarray(m.curved_midpoints, float) for m in meshes if m.curved_edges is not None]
    return {"curved_edges": np.concatenate(edges), "curved_midpoints": np.concatenate(midpoints)}


def _length(line: FloatArray) -> float:
    return float(np.linalg.norm(np.diff(line, axis=0), axis=1).sum())


def device_problem(device: DeviceMesh, law: HyperelasticLaw, thread: HoopThread | None = None,
                   backbone: HoopThread | None = None) -> tuple[PressureProblem, Ties, int]:
    """The pressure problem of the whole device (:func:`section_problem`'s, the joints' ties as its springs, the
    ``backbone`` thread along the axis when given), its ties, and how many of its fibres are the hoop thread's
    (the backbone's follow)."""
    problem = section_problem(device.whole, law, thread)
    mesh = problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    ties = tie_joints(mesh, joints_of(device), 3.0 * law.mu_kpa)  # incompressible: E = 3 mu
    hoops = 0 if problem.fibres is None else len(problem.fibres.faces)
    if len(device.parts) > 1:
        problem = replace(problem, springs=ties.springs())
    if backbone is not None:
        pools = [np.arange(device.tet_start[i], device.tet_start[i + 1]) for i in range(len(device.parts))]
        spine = backbone_fibres(mesh, [p.mesh.centerline for p in device.parts], pools, backbone, 3.0 * law.mu_kpa)
        problem = replace(problem, fibres=thread_fibres([problem.fibres, spine]))
    return problem, ties, hoops


def joints_of(device: DeviceMesh) -> list[tuple[IntArray, IntArray]]:
    """Per joint, the corner faces (k, 3) of the proximal section's tip and of the distal section's base."""
    out = []
    for i in range(len(device.parts) - 1):
        tip = joint_faces(device.whole.tets[device.tet_start[i]:device.tet_start[i + 1]],
                          tip_nodes(device, i))
        base = joint_faces(device.whole.tets[device.tet_start[i + 1]:device.tet_start[i + 2]],
                           base_nodes(device, i + 1))
        out.append((tip, base))
    return out


def base_nodes(device: DeviceMesh, i: int) -> IntArray:
    """Corner nodes (global) of section i's base layer."""
    return device.node_start[i] + np.flatnonzero(device.parts[i].mesh.base)


def tip_nodes(device: DeviceMesh, i: int) -> IntArray:
    """Corner nodes (global) of section i's tip layer (its last level along the centerline)."""
    level = device.parts[i].mesh.node_l
    return device.node_start[i] + np.flatnonzero(np.isclose(level, level.max(), rtol=0.0, atol=1e-6))


def roundoff_floor_mn(problem: PressureProblem) -> float:
    """The residual (mN) below which a Newton iteration cannot go for the threads' rounding (0 without threads).

    A thread's force is ``E_t A_t e``, its strain found from positions of size X (mm) over fibre pieces as short
    as h: each fibre's force carries a noise of about ``eps X / h`` of ``E_t A_t``, and F fibres' noise adds up
    as ``sqrt(F)``.  The floor is ``FIBRE_ROUNDOFF`` times that.  Measured stalls: a straight two-section device
    near the origin with a 0.3 mm, 70 GPa thread (``E_t A_t`` = 4.9e6 mN), 1.0e-6 to 1.2e-6 mN; the demo's
    device in the patient's coordinates, 2.7e-5 to 3.0e-5 mN.  The section solves' absolute tolerance (1e-10 mN)
    is below either.
    """
    fibres = problem.fibres
    if fibres is None:
        return 0.0
    size = float(np.abs(problem.mesh.points).max())
    reach = np.abs(fibres.directions).sum(axis=2).max()  # 1 / h: the largest |dx/dX| a unit position error makes
    noise = np.finfo(float).eps * size * float(reach) * np.sqrt(len(fibres.faces))
    return FIBRE_ROUNDOFF * noise * float(fibres.axial_stiffness_mn.max())


@dataclass(frozen=True)
class Located:
    """Where every section's centerline samples lie: per section the elements (global) and barycentric weights."""

    elements: tuple[IntArray, ...]
    weights: tuple[FloatArray, ...]


def locate_samples(device: DeviceMesh, mesh: QuadraticMesh) -> Located:
    """Each section's centerline samples located in its own elements (MeshError: a sample outside the material);
    in curved elements where ``mesh`` (the whole device's quadratic mesh) maps them."""
    elements, weights = [], []
    for i, part in enumerate(device.parts):
        tets = make_tet_mesh(part.mesh.points, part.mesh.tets)
        found = [locate(tets, part.samples[k:k + LOCATE_BATCH]) for k in range(0, len(part.samples), LOCATE_BATCH)]
        elements.append(np.concatenate([e for e, _ in found]) + device.tet_start[i])
        weights.append(curved_barycentric(mesh, elements[-1], np.concatenate([w for _, w in found]), part.samples))
    return Located(tuple(elements), tuple(weights))


def carried_samples(problem: PressureProblem, located: Located, samples: Sequence[FloatArray], u: FloatArray
                    ) -> list[FloatArray]:
    """Each section's centerline samples (n_i, 3) mm carried by the nodal displacement ``u`` (N, 3) mm."""
    mesh = problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    return [s + np.einsum("na,nai->ni", shape_values(w), u[mesh.cells[e]])
            for s, e, w in zip(samples, located.elements, located.weights, strict=True)]


@dataclass(frozen=True)
class DeviceSolve:
    """The equilibrium of a device at its pressures, and how it was reached."""

    device: DeviceMesh
    problem: PressureProblem
    ties: Ties
    hoop_fibres: int  #: the problem's first fibres are the hoop thread's; the backbone's follow
    located: Located
    pressures_kpa: FloatArray  #: (k + m,) the chambers' pressures, then the feeds'
    u: FloatArray  #: (N, 3) mm, every node's displacement
    record: SolveRecord  #: the load steps, their iterations and residuals
    load_factor: float = 1.0  #: the share of the asked pressures reached (below 1: the solve stopped there)
    stopped_because: str = ""  #: why it stopped short ("" when it reached the pressures)


def solve_device(device: DeviceMesh, law: HyperelasticLaw, pressures: FloatArray, settings: NewtonSettings,
                 thread: HoopThread | None = None, feed_pressures: FloatArray | None = None,
                 on_step: Callable[[float, list[float]], None] | None = None,
                 backbone: HoopThread | None = None, keep_stop: bool = False) -> DeviceSolve:
    """The device at chamber ``pressures`` (k,) kPa (feeds at ``feed_pressures`` (m,); None: their chambers').

    The pressures grow in load steps (:func:`~softdesign.mechanics.newton.solve_pressures`, ``settings``'
    steps and halvings, the first at most a tenth of the shear modulus and the steps before the last converged to
    1e-4: :func:`~softdesign.mechanics.load_steps.stepped_from_rest`), not in the cavities' volume
    (:mod:`~softdesign.mechanics.continuation`): a reinforced chamber's volume barely grows with its pressure,
    and a volume step asked for 8.5 kPa on the demo's device landed at 67-176 kPa.  ``on_step`` is told of
    every converged step (load factor, residuals); ``backbone``: the thread along the axis (``backbone:
    inextensible``), None: none.  ``keep_stop``: a solve that stops short
    returns its last equilibrium (``load_factor`` below 1, its pressures, ``stopped_because``) instead of
    raising, so that its figures at the largest load it held can be reported.

    Raises
    ------
    MeshError
        A section's named sets are wrong, a centerline sample lies outside the material, or a joint does not meet.
    SolveError
        A step failed after every halving (and not ``keep_stop``): the message gives the largest pressures reached.
    """
    pressures = np.asarray(pressures, float)
    if pressures.shape != (device.chamber_count,):
        raise ValueError(f"expected {device.chamber_count} chamber pressures, got shape {pressures.shape}")
    feeds = pressures[device.feed_chambers] if feed_pressures is None else np.asarray(feed_pressures, float)
    if feeds.shape != (device.feed_count,):
        raise ValueError(f"expected {device.feed_count} feed pressures, got shape {feeds.shape}")
    problem, ties, hoops = device_problem(device, law, thread, backbone)
    assert isinstance(problem.mesh, QuadraticMesh)
    located = locate_samples(device, problem.mesh)
    every = np.concatenate([pressures, feeds])
    settings = stepped_from_rest(replace(settings, atol=max(settings.atol, roundoff_floor_mn(problem))),
                                 float(np.abs(every).max()), law.mu_kpa)
    try:
        u, record = solve_pressures(problem, every, settings, solver=TangentSolver(), on_step=on_step)
    except SolveStopped as err:
        at = ", ".join(f"{err.load_factor * p:.4g}" for p in every)
        message = f"the whole device: the solve stopped at {at} kPa (load factor {err.load_factor:.4g}, the " \
                  f"largest it reached): {err}"
        if not keep_stop or err.load_factor <= 0.0:
            raise SolveError(message) from err
        return DeviceSolve(device, problem, ties, hoops, located, err.load_factor * every, err.displacement,
                           err.record, err.load_factor, message)
    return DeviceSolve(device, problem, ties, hoops, located, every, u, record)
