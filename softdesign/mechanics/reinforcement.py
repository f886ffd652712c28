"""Hoop reinforcement: a thread wound round each chamber, as a fibre membrane on the chamber's wall that takes
no more compression than it can before it buckles.

Formulation
    The thread is wound round the chamber's core before casting, so it lies
    on the chamber's wall.  It is smeared into a membrane on the wall's
    6-node faces: at each quadrature point of a face the fibre's reference
    direction ``a0`` (a unit vector in the wall's tangent plane) is carried
    by the wall's surface map, ``a = dx/dS`` along ``a0``, and the fibre
    stretch is ``lambda = |a|``, ``I4 = |a|^2``.  With ``e = (I4 - 1) / 2``
    (the Green strain along the thread, ``eps`` at small strain) the energy
    per reference wall area is

        W = k e^2 / 2                                   when e >= -e_b,
        W = k e_b^2 / 2 - k e_b (e + e_b)               below (buckled: a constant force),

    with ``k = E_t A_t / pitch`` (kPa mm = mN/mm): the thread's axial
    stiffness ``E_t A_t`` (``A_t = pi d^2 / 4``) per unit of chamber length
    that each turn covers.  The thread's tension is ``T = E_t A_t e`` (its
    Biot form ``lambda dW/dI4 * 2 pitch`` is the same to first order).
Why not tension-only
    A thread cannot push, but a thread *bonded in silicone* is held sideways
    by it and carries compression up to its buckling load on that elastic
    foundation (Winkler's beam: ``P_b = 2 sqrt(k_f E_t I_t)``, foundation
    modulus ``k_f ~ E_m`` the matrix's Young's modulus, ``I_t = pi d^4 / 64``),
    a strain ``e_b = P_b / (E_t A_t)`` of 4.4e-3 for a 0.2 mm, 2 GPa
    thread in a silicone of E_m = 120 kPa.  Beyond it the buckled thread's force stays at
    ``P_b`` (``W' `` constant, ``W'' = 0``).  A strictly tension-only law
    (``e_b = 0``) was tried first: Newton cycled, the threads of the
    unpressurised chambers (hoop strains of +-1e-6) switching a stiffness
    1000 times the wall's on and off at every iteration.
Direction
    The winding is a helix of pitch ``pitch`` round a chamber of radius r:
    its angle from the chamber's axis is ``beta = atan(2 pi r / pitch)``
    (near hoop, 90 degrees, for a fine pitch).  ``a0 = cos(beta) t + sin(beta)
    (n x t)``, with n the wall's normal and t the chamber's axis projected
    into the wall.  One helix, one hand: a right-handed winding (its twist
    coupling goes as ``cos(beta)``, 1 % at a pitch of a tenth of the
    circumference).  The caps of a chamber (faces whose normal is within 45
    degrees of the axis) carry no winding.
End patches
    A bare cap is a cavity's end in rubber, which has no equilibrium past
    about 5 mu / 2 (a spherical cavity's limit; the test section below stops
    at 95 kPa, 2.4 mu).  With ``patched_ends`` each cap face carries two
    crossed families of the same thread at the same pitch, each with the
    winding's energy: a disc woven of the thread laid on each end of the
    core before casting.  A flat patch carries the cap's pressure as a
    membrane once it dishes, so its tension is not the winding's
    ``P r pitch``; the finite elements report it (the largest tension is
    over every fibre, winding and patches).
Assumptions
    The thread is bonded to the silicone (no slip), thin against the wall
    (its bending stiffness is left out but for its buckling), linear elastic,
    and every wall face has the same pitch.
Derivatives
    With ``a = sum_b D_b x_b`` (``D_b = alpha dN_b/dxi + beta dN_b/deta``,
    constant per point) and ``W`` as a function of I4 (``W' = k e / 2``,
    ``W'' = k / 4``, or ``-k e_b / 2`` and 0 when buckled),
    ``f_b = sum_q w 2 W' a D_b`` and ``K_bc = sum_q w D_b D_c [4 W'' a (x) a + 2 W' I]``:
    the exact Hessian but at the buckling kink (the tests check it against finite differences).
    The control's term ``k w (e_q - e_0)^2 / 2`` (below) adds ``k w d_q (g_q - g_0)`` to the
    forces and ``k w [(g_q - g_0) (x) (g_q - g_0) + d_q (D_q D_q - D_0 D_0) I]`` to the Hessian, with
    ``d_q = e_q - e_0`` and ``g_q = a_q D_q`` (the strain's gradient at point q).
Integration: the centroid, with hourglass control on six points
    A thread of ``k`` ~ 1e5 times the wall's stiffness is nearly a
    constraint.  Integrated by the pressure's six-point rule alone, it imposes
    three hoop conditions per face (the hoop strain of a quadratic face is
    linear on it), more than a coarse wall's nodes can meet with the
    silicone's own deformation (the wall locks, as a fully integrated nearly
    incompressible solid does), and the points' buckling kinks switch: on
    the whole sample device with patched ends, asked 446 kPa, Newton cycled
    (residuals 1e0-1e3 mN for 12 iterations) and the steps halved until the
    solve crept, 1.3 % of the load in six minutes.  At the face's centroid
    alone (reduced
    integration, a fibre tension constant per face, as Malkus and Hughes
    1978 for incompressibility) the device converges in 5-6 iterations a step,
    but the rule has a zero-energy (hourglass) mode: a face's corner nodes
    moving out and its midside nodes in leaves the centroid's hoop length
    unchanged.  A chamber's end, where the wall carries the largest stretch,
    falls into it: on the reinforced test section (below) the corner-node
    rings alternated along the chamber at radii 1.50-1.74 and 0.25-0.55 mm
    (from 1.0) with the centroids' thread strain under 1.8e-3, and the
    section's largest pressure was the mode's, not the rubber's.
    The rule here is the centroid, with hourglass control on the six points
    (Belytschko and Bindeman's stabilised one-point elements): the energy is
    ``w_c W(e_c) + s sum_q w_q k (e_q - e_c)^2 / 2`` per face, the thread's
    law at the centroid and a penalty on each point's departure from the
    centroid's strain, a share ``s`` = ``FIBRE_STABILISATION``
    (:class:`FibreMembrane`'s ``anchored``).  The mode stores ``s`` of the
    full rule's energy, a stiffness ``s k`` still 50-5000 times the wall's
    ``E t`` (``k`` is 1e3-1e5 times it for the threads here); a uniform
    strain stores the law's energy alone.  The thread's tension is the
    centroid's: the points' departures are the control's, not the thread's.
    Why a penalty on the departure rather than a share of the law at the six
    points (``(1 - s) w_c W(e_c) + s sum_q w_q W(e_q)``, the rule until round
    4, the same energy in the elastic range): a chamber's end drives the
    mode however it is held (at 160 kPa on the patched test section below,
    the six points' strains ran from -1.8 to +6.2 % on faces whose centroid
    read 0.1 %, with either form), and as a share of the law those points
    buckled and unbuckled (kinks that Newton steps across) and reported their
    strain as the thread's tension: 3.9 N on that section, where the
    centroids carried 69 mN and the rod model's ``P r pitch`` is 80 mN (the
    whole sample device read 20.5 N at 69 % of P*).  The penalty is smooth and
    its points carry no tension.  The share is the smallest
    that holds the mode (measured with the share of the law, the same
    energy in the elastic range): one chamber of the 12 mm test section (R 5 mm, a
    2 mm chamber at 2.5 mm, 1.5 mm end walls, mu 40 kPa) pressurised past
    its bare ends' limit stops at 75.4 kPa on the centroid alone (the mode),
    90.4 kPa with 1 %, 95.1 kPa with 5 % and 98.8 kPa with the six-point rule
    alone, near the 2.5 mu = 100 kPa past which a cavity in this rubber has
    no equilibrium.  5 % is within 4 % of the full rule's limit; 1 % is 8.5 %
    short.  Where a chamber has few wall faces the centroid alone also left
    the hoop slack: the per-chamber sample's first section (0.8-1.1 mm
    chambers in a 3 mm mesh) bent 9.7 % less than the rod model, 2.4 % with
    six points alone, 2.7 % with the 5 % share.  The other known answers are
    the tests' (the long section against ``P A d / (E I)``, symmetry, two
    opposite sections, the rod model of a one-section device).
Newton's method
    The derivative's fibre tension is the mixed method's (as the element
    pressure in :mod:`softdesign.mechanics.newton`): a fibre strain carried
    from iteration to iteration by its linearization
    (:meth:`FibreMembrane.linearized_strains`), not the strain of the new
    displacement, which a linear update overstretches at second order
    through the wall's rotation (a stretch ``|w|^2 / 2`` of 1e-3 at 4 kPa
    on the sample device, times ``k``).  The residual is the displacement's.
Strain from the displacement
    The strain is computed from the displacement ``u``, never from the
    positions: with ``A = sum_b D_b X_b`` (the unit reference fibre, kept)
    and ``w = sum_b D_b u_b``, ``e = A . w + |w|^2 / 2`` (the same Green
    strain, ``a = A + w``).  From the positions, ``|a|^2 - 1`` cancels two
    numbers near 1 that are each sums of terms of the size of the coordinates
    over the element (26 mm over 1 mm on the demo's section): a strain
    round-off of 1e-13 at rest, which a thread of ``k`` ~ 1e7 mN/mm turns
    into spurious forces of 8e-6 mN.  Newton could not go below them, and at
    a small load step (10 kPa / 128 on the demo's section, a pressure load of
    0.78 mN) the step's tolerance (1e-8 of the load) was 1000 times smaller:
    every step failed near 3e-6 mN.  From ``w`` the round-off is relative to
    the strain itself and the residual falls to the silicone's floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from softdesign.mechanics.quadratic_pressure import TRI_POINTS, TRI_WEIGHTS, triangle_shapes
from softdesign.mechanics.tets import node_dofs, summed
from softdesign.types import FloatArray, IntArray

#: A wall face whose normal is within this angle of the chamber's axis is a cap: no thread on it, rad.
CAP_ANGLE_RAD = math.pi / 4

#: Hourglass control: the stiffness of each point's departure from the centroid's strain, as a share of the
#: six-point rule's (see "Integration" in the module's docstring).
FIBRE_STABILISATION = 0.05
#: The fibres' rule on a 6-node face: the thread's law at the centroid (weight 1/2, the reference triangle's area)
#: and the stabilisation's deviations from it at the pressure's six points (weights s times theirs, which sum to 1/2).
_, FIBRE_DXI, FIBRE_DETA = triangle_shapes(np.vstack([[[1.0 / 3.0, 1.0 / 3.0]], TRI_POINTS]))
FIBRE_WEIGHTS = np.concatenate([[0.5], FIBRE_STABILISATION * TRI_WEIGHTS])
#: The rule's first point carries the law and the others the deviations from it (:class:`FibreMembrane`'s
#: ``anchored``); False: the law at every point (a plain quadrature rule, for comparisons).
FIBRE_ANCHORED = True


def anchored_rule() -> bool:
    """Whether fibres built now take the anchored rule (:data:`FIBRE_ANCHORED`, and a rule of more than one point),
    read at each call so that a comparison that swaps the rule's constants builds every fibre set alike."""
    return FIBRE_ANCHORED and len(FIBRE_WEIGHTS) > 1


@dataclass(frozen=True)
class HoopThread:
    """The thread wound round each chamber (mm, kPa).

    Attributes
    ----------
    pitch_mm : axial distance between turns, mm (> 0)
    diameter_mm : the thread's diameter, mm (> 0)
    modulus_kpa : the thread's Young's modulus in tension, kPa (> 0)
    patched_ends : a woven patch of the same thread, two crossed families each at the pitch, over each chamber's
        ends (the caps); False: bare caps
    """

    pitch_mm: float
    diameter_mm: float
    modulus_kpa: float
    patched_ends: bool = False

    def __post_init__(self) -> None:
        values = (self.pitch_mm, self.diameter_mm, self.modulus_kpa)
        if not all(math.isfinite(v) and v > 0 for v in values):
            raise ValueError(f"a hoop thread needs pitch_mm, diameter_mm and modulus_kpa > 0 and finite; got "
                             f"{self.pitch_mm}, {self.diameter_mm}, {self.modulus_kpa}")

    @property
    def axial_stiffness_mn(self) -> float:
        """``E_t A_t``, mN (kPa mm^2): the thread's tension per unit strain."""
        return self.modulus_kpa * math.pi * self.diameter_mm**2 / 4.0

    @property
    def stiffness_mn_per_mm(self) -> float:
        """``k = E_t A_t / pitch``, mN/mm: the membrane's hoop stiffness."""
        return self.axial_stiffness_mn / self.pitch_mm

    def buckling_strain(self, matrix_modulus_kpa: float) -> float:
        """The compressive strain at which the thread buckles in a matrix of Young's modulus ``matrix_modulus_kpa``:
        ``2 sqrt(E_m E_t I_t) / (E_t A_t)`` (a beam on a Winkler foundation of modulus E_m)."""
        bending = self.modulus_kpa * math.pi * self.diameter_mm**4 / 64.0
        return 2.0 * math.sqrt(matrix_modulus_kpa * bending) / self.axial_stiffness_mn

    def winding_angle_rad(self, radius_mm: float) -> float:
        """The helix's angle from the chamber's axis round a chamber of ``radius_mm``: ``atan(2 pi r / pitch)``."""
        return math.atan2(2.0 * math.pi * radius_mm, self.pitch_mm)


@dataclass(frozen=True)
class FibreMembrane:
    """Fibres on 6-node faces (or any fixed number of node slots): the reinforcement's energy term of a pressure
    problem.

    Attributes
    ----------
    faces : (F, 6) int, the 6-node faces carrying fibres
    directions : (F, Q, 6) float, ``D_b``: the fibre vector ``a = sum_b D_b x_b`` at each point
    reference : (F, Q, 3) float, ``A = sum_b D_b X_b``: the unit fibre at rest
    weights : (F, Q) float, mm^2: quadrature weight times the reference area's Jacobian
    stiffness : (F,) float, mN/mm: ``k`` of each face
    axial_stiffness_mn : (F,) float, mN: ``E_t A_t`` (for the thread's tension)
    buckling_strain : (F,) float: ``e_b`` >= 0, the compression the thread takes before it buckles
    anchored : the thread's law at point 0 alone, the other points storing ``k w (e_q - e_0)^2 / 2`` (the
        stabilisation of the module's docstring, "Integration"); False: the law at every point
    """

    faces: IntArray
    directions: FloatArray
    reference: FloatArray
    weights: FloatArray
    stiffness: FloatArray
    axial_stiffness_mn: FloatArray
    buckling_strain: FloatArray
    anchored: bool = False

    def fibre_vectors(self, displacement: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The deformed fibre vectors ``a`` (F, Q, 3) and the Green strains ``e`` (F, Q) along them under the nodes'
        ``displacement`` (N, 3) mm (from the displacement: the module's docstring)."""
        w = np.einsum("fqb,fbi->fqi", self.directions, displacement[self.faces])
        e = np.einsum("fqi,fqi->fq", self.reference, w) + 0.5 * np.einsum("fqi,fqi->fq", w, w)
        return self.reference + w, e

    def strains_at(self, displacement: FloatArray) -> FloatArray:
        """The thread's Green strain ``e = (I4 - 1) / 2`` (F, Q) at each point under ``displacement`` (N, 3) mm."""
        return self.fibre_vectors(displacement)[1]

    @property
    def law_weights(self) -> FloatArray:
        """The weights (F, Q) mm^2 of the thread's law at each point (their sum: the wall's area times the number of
        families on it); the stabilisation's are not among them."""
        return self._split_weights()[0]

    def _split_weights(self) -> tuple[FloatArray, FloatArray]:
        """The weights (F, Q) of the thread's law at each point and of the anchored stabilisation's deviations
        (zero at point 0; all zero when not ``anchored``)."""
        if not self.anchored:
            return self.weights, np.zeros_like(self.weights)
        law = np.zeros_like(self.weights)
        law[:, 0] = self.weights[:, 0]
        penalty = self.weights.copy()
        penalty[:, 0] = 0.0
        return law, penalty

    def energy_at(self, displacement: FloatArray) -> float:
        """The stored energy, mN mm, under ``displacement`` (N, 3) mm."""
        e, e_b = self.strains_at(displacement), self.buckling_strain[:, None]
        law, penalty = self._split_weights()
        per_area = np.where(e >= -e_b, 0.5 * e**2, 0.5 * e_b**2 - e_b * (e + e_b))
        deviation = 0.5 * (e - e[:, :1]) ** 2
        return float(np.sum((law * per_area + penalty * deviation) * self.stiffness[:, None]))

    def _first(self, e: FloatArray) -> FloatArray:
        """``dE/dI4`` at each point (F, Q), mN/mm times mm^2: the law's at its points, and each deviation's
        ``k w (e_q - e_0) / 2`` at its point q and, with the opposite sign, at point 0."""
        law, penalty = self._split_weights()
        k = self.stiffness[:, None]
        first = 0.5 * np.maximum(e, -self.buckling_strain[:, None]) * law * k
        pulls = 0.5 * (e - e[:, :1]) * penalty * k
        first = first + pulls
        first[:, 0] -= pulls.sum(axis=1)
        return first

    def force_and_tangent_at(self, displacement: FloatArray, want_tangent: bool, strain: FloatArray | None = None
                             ) -> tuple[FloatArray, sp.csr_matrix | None]:
        """Internal forces (3N,) mN of the fibres under ``displacement`` (N, 3) mm and, if asked, their derivative
        (3N, 3N) mN/mm.

        ``strain`` (F, Q), when given, is the mixed Newton method's fibre strain (:meth:`linearized_strains`): the
        derivative takes its tension (the geometric part ``2 W' I``) and its regime (stretched or buckled) in
        place of the displacement's own; the forces are always those of the displacement.
        """
        a, e = self.fibre_vectors(displacement)
        first = self._first(e)
        forces = np.einsum("fq,fqi,fqb->fbi", 2.0 * first, a, self.directions)
        dofs = node_dofs(self.faces)  # 18 on 6-node faces; any node count per fibre assembles alike
        width = dofs.shape[1]
        n = displacement.size
        f = summed(dofs, forces.reshape(len(self.faces), width), n)
        if not want_tangent:
            return f, None
        if strain is not None:
            e, first = strain, self._first(strain)
        law, penalty = self._split_weights()
        k = self.stiffness[:, None]
        # the material part: k w e' e'^T, with e' = a D (the law's, but none when buckled) and the deviations'
        grads = np.einsum("fqi,fqb->fqbi", a, self.directions).reshape(len(self.faces), -1, width)
        elastic = np.where(e >= -self.buckling_strain[:, None], law, 0.0) * k
        deviations = grads - grads[:, :1]
        blocks = (np.einsum("fq,fqm,fqn->fmn", elastic, grads, grads)
                  + np.einsum("fq,fqm,fqn->fmn", penalty * k, deviations, deviations))
        # the geometric part: 2 dE/dI4 D_b D_c I
        geometric = np.einsum("fq,fqb,fqc->fbc", 2.0 * first, self.directions, self.directions)
        blocks += np.einsum("fbc,ik->fbick", geometric, np.eye(3)).reshape(blocks.shape)
        rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
        cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
        return f, sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n, n))

    def linearized_strains(self, displacement: FloatArray, step: FloatArray) -> FloatArray:
        """The Green strains (F, Q) after the displacement ``step`` (N, 3) mm from ``displacement`` (N, 3) mm, to
        first order: ``e + a . sum_b D_b step_b``: the mixed Newton method's fibre strain (module docstring)."""
        a, e = self.fibre_vectors(displacement)
        change = np.einsum("fqb,fbi->fqi", self.directions, step[self.faces])
        return np.asarray(e + np.einsum("fqi,fqi->fq", a, change), np.float64)

    def thread_tension_at(self, displacement: FloatArray) -> FloatArray:
        """The thread's force (F,) mN of each fibre under ``displacement`` (N, 3) mm, ``E_t A_t e`` (tension > 0; at
        least ``-E_t A_t e_b``): at the law's points (when ``anchored``, point 0 alone: the others' deviations are
        the stabilisation's, not a tension), the largest."""
        law, _ = self._split_weights()
        tension = self.axial_stiffness_mn[:, None] * np.maximum(self.strains_at(displacement),
                                                                -self.buckling_strain[:, None])
        return np.asarray(np.where(law > 0, tension, -np.inf).max(axis=1), np.float64)


def hoop_membrane(points: FloatArray, faces: IntArray, axes: FloatArray, radii_mm: FloatArray,
                  thread: HoopThread, matrix_modulus_kpa: float) -> FibreMembrane:
    """The hoop thread's membrane on chamber walls (see the module's docstring), and its end patches' if
    ``thread.patched_ends``.

    Parameters
    ----------
    points : (N, 3) float, mm -- reference nodes (corners and midpoints)
    faces : (F, 6) int -- chamber wall faces (any winding)
    axes : (F, 3) float -- the chamber's axis direction at each face (need not be unit)
    radii_mm : (F,) float, mm -- the radius of each face's chamber (for the winding angle)
    thread : the thread
    matrix_modulus_kpa : the silicone's Young's modulus, kPa (holds the thread sideways: its buckling strain)

    Faces whose normal lies within ``CAP_ANGLE_RAD`` of the axis are the chamber's caps: no winding on them; a
    patch's two crossed families when the ends are patched.  The fibres are the side faces' (in ``faces``'s
    order), then each patched cap's twice (its two families).
    """
    wall = _WallGeometry.of(points, faces)
    t = np.asarray(axes, float) / np.linalg.norm(axes, axis=1)[:, None]
    side = np.abs(np.einsum("fqi,fi->fq", wall.normal, t)).max(axis=1) < math.cos(CAP_ANGLE_RAD)
    n = wall.normal[side]
    along = t[side, None, :] - np.einsum("fqi,fi->fq", n, t[side])[..., None] * n
    along /= np.linalg.norm(along, axis=2)[..., None]
    beta = np.array([thread.winding_angle_rad(float(r)) for r in radii_mm[side]])[:, None, None]
    parts = [(side, np.cos(beta) * along + np.sin(beta) * np.cross(n, along))]
    if thread.patched_ends and not side.all():
        parts += [(~side, a0) for a0 in _patch_directions(wall.normal[~side])]
    chosen = np.concatenate([np.flatnonzero(keep) for keep, _ in parts])
    fibres = [wall.fibres(np.flatnonzero(keep), a0) for keep, a0 in parts]
    count = len(chosen)
    return FibreMembrane(np.asarray(faces, np.int64)[chosen], np.concatenate([d for d, _ in fibres]),
                         np.concatenate([r for _, r in fibres]), (FIBRE_WEIGHTS[None] * wall.area)[chosen],
                         np.full(count, thread.stiffness_mn_per_mm), np.full(count, thread.axial_stiffness_mn),
                         np.full(count, thread.buckling_strain(matrix_modulus_kpa)),
                         anchored_rule())


def _patch_directions(normal: FloatArray) -> tuple[FloatArray, FloatArray]:
    """A woven patch's two crossed families (F, Q, 3) in the tangent planes of normals ``normal`` (F, Q, 3): the
    global axis least aligned with each face's normal, projected into its plane, and the normal's cross with it."""
    pick = np.argmin(np.abs(normal).mean(axis=1), axis=1)  # per face, so that its points share one weave
    helper = np.eye(3)[pick][:, None, :]
    first = helper - np.einsum("fqi,fqi->fq", normal, np.broadcast_to(helper, normal.shape))[..., None] * normal
    first /= np.linalg.norm(first, axis=2)[..., None]
    return first, np.cross(normal, first)


@dataclass(frozen=True)
class _WallGeometry:
    """6-node faces' surface map at the fibres' rule points: tangents ``dX/dxi``, ``dX/deta``, unit normals and area
    Jacobians (F, Q), reference mm."""

    nodes: FloatArray  #: (F, 6, 3) the faces' reference nodes, mm
    x_xi: FloatArray
    x_eta: FloatArray
    normal: FloatArray
    area: FloatArray

    @classmethod
    def of(cls, points: FloatArray, faces: IntArray) -> _WallGeometry:
        x = np.asarray(points, float)[faces]
        x_xi, x_eta = np.einsum("qb,fbi->fqi", FIBRE_DXI, x), np.einsum("qb,fbi->fqi", FIBRE_DETA, x)
        normal = np.cross(x_xi, x_eta)
        area = np.linalg.norm(normal, axis=2)
        return cls(x, x_xi, x_eta, normal / area[..., None], area)

    def fibres(self, rows: IntArray, a0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``D_b`` (k, Q, 6) and the unit reference fibre ``A`` (k, Q, 3) along the tangent directions ``a0``
        (k, Q, 3) on faces ``rows``: ``a0 = alpha X_xi + beta X_eta``, the metric's inverse on the tangents'
        projections."""
        tangents = (self.x_xi[rows], self.x_eta[rows])
        g = np.stack([np.stack([np.einsum("fqi,fqi->fq", u, v) for v in tangents], -1) for u in tangents], -2)
        rhs = np.stack([np.einsum("fqi,fqi->fq", u, a0) for u in tangents], axis=-1)
        coeff = np.linalg.solve(g, rhs[..., None])[..., 0]  # (k, Q, 2)
        directions = coeff[..., :1] * FIBRE_DXI[None] + coeff[..., 1:] * FIBRE_DETA[None]
        reference = np.einsum("fqb,fbi->fqi", directions, self.nodes[rows])
        length = np.linalg.norm(reference, axis=2)[..., None]  # 1 within the metric solve's round-off (1e-13)
        return directions / length, reference / length
