"""What a whole-device equilibrium gives: its centerline, each section's arc, its tip frame, stress, stretch, thread.

- The deformed centerline: each section's unloaded centerline samples
  carried by the displacement (the quadratic elements' shapes), base to tip,
  the joints' duplicate points dropped.
- Each section's best arc (:func:`softdesign.mechanics.section.arc_of`) in its
  own deformed base frame: the unloaded frame (N, B, T) at its base turned by
  the rotation that best carries its base face's nodes (a least-squares fit,
  Kabsch's), the origin its first centerline point.  This is the frame a
  constant-curvature chain composes from (seed 003): the arc's phi is
  measured from the turned N towards the turned B.
- The tip frame: the last section's tip face's rotation applied to the body's
  unloaded frame there, at the centerline's last point.
- The largest principal stretch and Cauchy stress over the quadrature points,
  with the section and the element's unloaded centroid; the largest tension
  (mN) of the hoop thread and of the backbone thread, with their sections;
  the ties' largest gap (the penalty's error).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.continuum.laws import cauchy_stress
from softdesign.mechanics.device import DeviceSolve, base_nodes, carried_samples, tip_nodes
from softdesign.mechanics.quadratic import QuadraticMesh, quadratic_state
from softdesign.mechanics.section import arc_of
from softdesign.types import FloatArray


def rotation_between(reference: FloatArray, deformed: FloatArray) -> FloatArray:
    """The rotation (3, 3) that best carries ``reference`` (n, 3) onto ``deformed`` (n, 3), centroids removed."""
    a = reference - reference.mean(axis=0)
    b = deformed - deformed.mean(axis=0)
    u, _, vt = np.linalg.svd(a.T @ b)
    d = np.sign(np.linalg.det(vt.T @ u.T))
    return vt.T @ np.diag([1.0, 1.0, d]) @ u.T


@dataclass(frozen=True)
class SectionArc:
    """A section's best arc in its deformed base frame (1/mm, rad, mm) and how far the centerline misses it."""

    kappa: float
    phi: float
    length: float
    misfit_max_mm: float


@dataclass(frozen=True)
class Extreme:
    """The largest value of a field, the section (0 at the base) holding it and where (unloaded, mm)."""

    value: float
    section: int
    at: FloatArray


@dataclass(frozen=True)
class DeviceFigures:
    """A whole-device equilibrium's figures (mm, rad, kPa, mN)."""

    centerline: FloatArray  #: (m, 3) deformed, base to tip, device frame
    rest_centerline: FloatArray  #: (m, 3) the same points unloaded
    section_of_point: FloatArray  #: (m,) int, the section of each centerline point
    arcs: tuple[SectionArc, ...]
    base_frames: FloatArray  #: (n, 3, 3) each section's deformed base frame, columns (N, B, T)
    tip_frame: FloatArray  #: (4, 4) the deformed tip frame in the device frame
    stretch: Extreme  #: largest principal stretch
    stress: Extreme  #: largest principal Cauchy stress, kPa
    thread: Extreme | None  #: largest hoop thread tension, mN (None: no thread)
    backbone: Extreme | None  #: largest backbone thread tension, mN (None: no backbone thread)
    tie_gap_mm: float  #: the joints' largest gap


def measure_device(solve: DeviceSolve) -> DeviceFigures:
    """The figures of a solved device (module docstring)."""
    device, problem, u = solve.device, solve.problem, solve.u
    mesh = problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    corners = mesh.linear.points
    moved = carried_samples(problem, solve.located, [p.samples for p in device.parts], u)
    arcs, frames = [], []
    for i, (part, line) in enumerate(zip(device.parts, moved, strict=True)):
        base = base_nodes(device, i)
        frame = rotation_between(corners[base], corners[base] + u[base]) @ part.base_frame
        frames.append(frame)
        along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(part.samples, axis=0), axis=1))])
        fractions = along / along[-1]  # exactly 1 at the tip (a pairwise sum may differ from the cumulative one)
        kappa, phi, length, miss, _ = arc_of((line - line[0]) @ frame, fractions)
        arcs.append(SectionArc(kappa, phi, length, miss))
    last = len(device.parts) - 1
    tip = tip_nodes(device, last)
    tip_frame = np.eye(4)
    tip_frame[:3, :3] = rotation_between(corners[tip], corners[tip] + u[tip]) @ device.parts[last].tip_frame
    tip_frame[:3, 3] = moved[-1][-1]
    keep = [line if i == 0 else line[1:] for i, line in enumerate(moved)]
    rest = [p.samples if i == 0 else p.samples[1:] for i, p in enumerate(device.parts)]
    sections = np.concatenate([np.full(len(k), i) for i, k in enumerate(keep)])
    stretch, stress = _material_extremes(solve)
    return DeviceFigures(np.concatenate(keep), np.concatenate(rest), sections, tuple(arcs), np.stack(frames),
                         tip_frame, stretch, stress, *_thread_extremes(solve), solve.ties.largest_gap_mm(u))


def _material_extremes(solve: DeviceSolve) -> tuple[Extreme, Extreme]:
    """The largest principal stretch and Cauchy stress (kPa) over the quadrature points, with section and place."""
    problem, u = solve.problem, solve.u
    mesh = problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    state = quadratic_state(mesh, problem.law, u)
    E, Q = state.J.shape
    F = state.F.reshape(E * Q, 3, 3)
    stretch = np.sqrt(np.linalg.eigvalsh(np.einsum("eki,ekj->eij", F, F))[:, -1]).reshape(E, Q).max(axis=1)
    sigma = cauchy_stress(problem.law, F, np.repeat(state.pressure, Q))
    principal = np.linalg.eigvalsh(sigma)[:, -1].reshape(E, Q).max(axis=1)
    out = []
    for field in (stretch, principal):
        e = int(np.argmax(field))
        at = mesh.linear.points[mesh.linear.tets[e]].mean(axis=0)
        out.append(Extreme(float(field[e]), solve.device.section_of_element(e), at))
    return out[0], out[1]


def _thread_extremes(solve: DeviceSolve) -> tuple[Extreme | None, Extreme | None]:
    """The largest tension (mN) of the hoop thread and of the backbone thread, each with its section and the
    fibre's unloaded centroid; None for a thread the device has not."""
    fibres = solve.problem.fibres
    if fibres is None:
        return None, None
    mesh = solve.problem.mesh
    assert isinstance(mesh, QuadraticMesh)
    tension = fibres.thread_tension_at(solve.u)
    out: list[Extreme | None] = []
    for part in (slice(0, solve.hoop_fibres), slice(solve.hoop_fibres, None)):
        if not len(tension[part]):
            out.append(None)
            continue
        f = int(np.argmax(tension[part])) + (part.start or 0)
        corner = int(fibres.faces[f, 0])  # a backbone piece may start at a midpoint: its edge's first corner
        corner = corner if corner < len(mesh.linear.points) else int(mesh.edges[corner - len(mesh.linear.points), 0])
        out.append(Extreme(float(tension[f]), solve.device.section_of_node(corner),
                           mesh.points[np.unique(fibres.faces[f])].mean(axis=0)))
    return out[0], out[1]
