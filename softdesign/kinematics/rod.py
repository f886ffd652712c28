"""A linear rod model of the cast body under cavity pressures: stiffness from each cross-section, loads from the
pressures, curvature and stretch integrated from the base frame (issue 41).  Pure numpy, no I/O.

The body
    A rod along its rest (q = 0, as cast) centreline, cut into ``k`` stations of
    rest length ``ds`` (mm), proximal first, each in one section (link).  A
    station's cross-section is the body's outer profile there (radii (m,) mm at
    the angles ``2 pi j / m`` from the body's N towards B: the fitted radius
    profile, not a circle) less every cavity crossing it (chambers, feeds, a
    supply line: circles of centre (2,) mm in (N, B) and radius mm).  Its area
    ``A``, first moment ``S`` (2,) and second-moment tensor ``I`` (2, 2) are
    taken about the centreline (not the centroid), exactly for the polygonal
    outer profile's smooth interpolant (trapezoid rule on a periodic integrand)
    and the circles.
Material
    Linear elastic, Young's modulus ``E`` (kPa): E = 3 mu for the presets'
    incompressible neo-Hookean fits, at small strain.
Loads
    Each cavity belongs to a pressure channel (``channel`` >= 0; -1: not
    pressurised).  Cut at a station, the fluid in a cavity of area ``A_j`` at
    ``p_j`` pushes the distal part by ``P A_j``: the material carries the axial
    force ``N = sum P A_j`` and the moment ``M = sum P A_j p_j`` about the
    centreline (feeds and supply lines included: a pressurised feed bends the
    sections it runs through).
Section law
    The fibre at ``y`` (2,) mm of the cross-section strains ``eps0 - w . y``:
    ``eps0`` the centreline's stretch, ``w`` (2,) 1/mm the rotation per rest
    length, pointing where the section bends (the centre of curvature; seed
    003's phi).  Equilibrium: ``E (A eps0 - S . w) + T = N`` and
    ``E (S eps0 - I w) + T y_t = M``.  ``backbone: free`` has no thread
    (``T = 0``): three equations, three unknowns.  ``backbone: inextensible``
    has a thread of negligible bending stiffness along ``y_t`` (the axis by
    default) that does not stretch (``eps0 - w . y_t = 0``) and carries the
    tension ``T``.
Shape
    Each station is a short arc of bending ``w ds`` (rad, towards
    ``atan2(w_B, w_N)``) and length ``ds (1 + eps0)``; the arcs compose from
    the base frame as seed 003's improved D-H (:func:`pcc.transform_from_arc`),
    exactly for a curvature constant over a station.

Assumptions: reinforced chambers (hoop threads stop their radial growth, so a
cavity's side-wall pressure loads the hoops and not the section; the hoops
add no axial stiffness); quasi-static; no gravity; no contact with the vessel;
small strains (linear in the pressures); no torsion (every load is axial).
Without reinforcement the model does not apply: in an incompressible body the
side-wall pressure cancels the end caps' moment over a long section,
kappa = (1 - 2 nu) P A d / (E I) = 0 at nu = 1/2 (issue 41).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from softdesign.kinematics import pcc
from softdesign.types import FloatArray, IntArray, Pose

Backbone = Literal["free", "inextensible"]
#: N per kPa mm^2 (kPa = 1e-3 N/mm^2).
NEWTON_PER_KPA_MM2 = 1e-3


@dataclass(frozen=True)
class Cavities:
    """The cavities of a body, one slot per physical cavity, at every station.

    Attributes
    ----------
    centers : (k, h, 2) float, mm, each cavity's centre in the station's (N, B)
    radii : (k, h) float, mm; 0 where the cavity does not cross the station
    channels : (h,) int, the pressure channel of each cavity, -1 when it is not pressurised
    """

    centers: FloatArray
    radii: FloatArray
    channels: IntArray


@dataclass(frozen=True)
class RodBody:
    """The rod: stations, their cross-sections' properties and the pressure loads per channel.

    Attributes
    ----------
    ds : (k,) mm, rest length of each station;  section : (k,) int, the section (link) of each station
    area : (k,) mm^2;  first : (k, 2) mm^3;  second : (k, 2, 2) mm^4 (about the centreline)
    force : (k, c) mm^2, the axial force per kPa of each channel;  moment : (k, c, 2) mm^3, its moment
    modulus_kpa : E;  backbone : free | inextensible;  thread_at : (2,) mm, the inextensible thread's place
    """

    ds: FloatArray
    section: IntArray
    area: FloatArray
    first: FloatArray
    second: FloatArray
    force: FloatArray
    moment: FloatArray
    modulus_kpa: float
    backbone: Backbone
    thread_at: FloatArray

    @property
    def channels(self) -> int:
        """How many pressure channels."""
        return int(self.force.shape[1])


def outline_properties(outer_radii: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Area (k,) mm^2, first moment (k, 2) mm^3 and second-moment tensor (k, 2, 2) mm^4 of star-shaped outlines.

    ``outer_radii`` (k, m) mm at angles ``2 pi j / m``: ``A = int r^2 / 2``, ``S = int r^3 / 3 (cos, sin)``,
    ``I = int r^4 / 4 (cos, sin)(cos, sin)^T`` over the angle (exact for a circle).
    """
    r = np.atleast_2d(np.asarray(outer_radii, float))
    m = r.shape[1]
    a = 2.0 * np.pi * np.arange(m) / m
    u = np.stack([np.cos(a), np.sin(a)], axis=1)  # (m, 2)
    da = 2.0 * np.pi / m
    area = np.sum(r**2, axis=1) * da / 2.0
    first = (r**3 @ u) * da / 3.0
    second = np.einsum("km,mi,mj->kij", r**4, u, u) * da / 4.0
    return area, first, second


def cavity_properties(centers: npt.ArrayLike, radii: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Area (..., h), first moment (..., h, 2) and second moment (..., h, 2, 2) of circles about the origin."""
    c, r = np.asarray(centers, float), np.asarray(radii, float)
    area = np.pi * r**2
    first = area[..., None] * c
    second = (np.pi * r**4 / 4.0)[..., None, None] * np.eye(2) + area[..., None, None] * (c[..., :, None]
                                                                                         * c[..., None, :])
    return area, first, second


def rod_body(ds: npt.ArrayLike, section: npt.ArrayLike, outer_radii: npt.ArrayLike, cavities: Cavities,
             modulus_kpa: float, backbone: Backbone, thread_at: npt.ArrayLike = (0.0, 0.0)) -> RodBody:
    """The rod of stations ``ds`` (k,) mm in sections ``section`` (k,), outlines (k, m) mm less ``cavities``.

    Raises ValueError for a modulus that is not > 0 or a cavity channel count that leaves a channel empty.
    """
    if not modulus_kpa > 0.0:
        raise ValueError(f"rod model: the modulus must be > 0 kPa, got {modulus_kpa}")
    area, first, second = outline_properties(outer_radii)
    a, s, i = cavity_properties(cavities.centers, cavities.radii)
    channels = np.asarray(cavities.channels, np.int64)
    count = int(channels.max()) + 1 if channels.size and channels.max() >= 0 else 0
    pick = (channels[:, None] == np.arange(count)[None, :]).astype(float)  # (h, c)
    force = a @ pick
    moment = np.einsum("khi,hc->kci", s, pick)
    return RodBody(np.asarray(ds, float), np.asarray(section, np.int64), area - a.sum(axis=1),
                   first - s.sum(axis=1), second - i.sum(axis=1), force, moment, float(modulus_kpa), backbone,
                   np.asarray(thread_at, float))


def strains(body: RodBody, pressures_kpa: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The centreline's stretch ``eps0`` (k,), the bending ``w`` (k, 2) 1/mm and the thread's tension (k,) N.

    ``pressures_kpa`` (c,): one pressure per channel, kPa.
    """
    p = np.asarray(pressures_kpa, float).reshape(-1)
    if p.shape != (body.channels,):
        raise ValueError(f"rod model: {body.channels} channel pressures expected, got {p.shape[0]}")
    n, m = body.force @ p, np.einsum("kci,c->ki", body.moment, p)
    k, e = len(body.ds), body.modulus_kpa
    if body.backbone == "free":
        matrix = np.zeros((k, 3, 3))
        matrix[:, 0, 0], matrix[:, 0, 1:] = body.area, -body.first
        matrix[:, 1:, 0], matrix[:, 1:, 1:] = body.first, -body.second
        x = np.linalg.solve(e * matrix, np.concatenate([n[:, None], m], axis=1)[..., None])[..., 0]
        return x[:, 0], x[:, 1:], np.zeros(k)
    y = body.thread_at
    matrix = np.zeros((k, 4, 4))
    matrix[:, 0, 0], matrix[:, 0, 1:3], matrix[:, 0, 3] = e * body.area, -e * body.first, 1.0
    matrix[:, 1:3, 0], matrix[:, 1:3, 1:3], matrix[:, 1:3, 3] = e * body.first, -e * body.second, y
    matrix[:, 3, 0], matrix[:, 3, 1:3] = 1.0, -y
    rhs = np.concatenate([n[:, None], m, np.zeros((k, 1))], axis=1)
    x = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    return x[:, 0], x[:, 1:3], x[:, 3] * NEWTON_PER_KPA_MM2


def station_poses(eps0: npt.ArrayLike, w: npt.ArrayLike, ds: npt.ArrayLike, base2world: npt.ArrayLike) -> Pose:
    """Frames (k + 1, 4, 4) at the stations' ends, the base first: each station an arc of bending ``w ds``."""
    eps0, w, ds = np.asarray(eps0, float), np.asarray(w, float), np.asarray(ds, float)
    length = ds * (1.0 + eps0)
    theta = np.hypot(w[:, 0], w[:, 1]) * ds
    phi = np.where(theta > 0.0, np.arctan2(w[:, 1], w[:, 0]), 0.0)
    kappa = np.divide(theta, length, out=np.zeros_like(theta), where=length > 0.0)
    steps = pcc.chain_transforms(pcc.transform_from_arc(kappa, phi, length))
    base = np.asarray(base2world, float)
    return np.concatenate([base[None], base @ steps])


def section_arcs(body: RodBody, poses: Pose, eps0: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Each section's equivalent arc (kappa 1/mm, phi rad, length mm) from its base and tip frames.

    The bending angle and plane are those of the rotation between the section's two frames (exact for a section
    that is one arc); the length is its stretched centreline's.
    """
    eps0 = np.asarray(eps0, float)
    sections = int(body.section.max()) + 1
    kappa, phi, length = np.zeros(sections), np.zeros(sections), np.zeros(sections)
    for i in range(sections):
        at = np.flatnonzero(body.section == i)
        rel = np.linalg.inv(poses[at[0]]) @ poses[at[-1] + 1]
        tangent = rel[:3, 2]
        theta = float(np.arctan2(np.hypot(tangent[0], tangent[1]), tangent[2]))
        length[i] = float(np.sum(body.ds[at] * (1.0 + eps0[at])))
        kappa[i] = theta / length[i]
        phi[i] = float(np.arctan2(tangent[1], tangent[0])) if theta > 0.0 else 0.0
    return kappa, phi, length


def hoop_tension_per_turn_n(pressure_kpa: npt.ArrayLike, radius_mm: npt.ArrayLike,
                            pitch_mm: npt.ArrayLike) -> FloatArray:
    """Tension (N) in one turn of a hoop thread round a chamber of ``radius_mm`` at ``pressure_kpa``.

    Thin-ring equilibrium: the pressure on a strip of the chamber ``pitch_mm`` long is carried by the turn
    wound over it, ``T = P r pitch`` (the silicone between turns is taken to carry none of it).
    """
    return (np.asarray(pressure_kpa, float) * np.asarray(radius_mm, float) * np.asarray(pitch_mm, float)
            * NEWTON_PER_KPA_MM2)
