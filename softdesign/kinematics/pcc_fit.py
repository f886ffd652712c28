"""One constant-curvature arc per link: how close a PCC actuator comes to the generalized design.

For a link from ``l_s`` to ``l_e`` at morph parameter ``q`` the generalized
design gives the backbone ``c(q, l)`` and frames ``F(q, l)``.  Expressed in the
link's start frame {S} = F(q, l_s) the backbone starts at the origin tangent
to z, exactly as a PCC section of seed 003 (:mod:`softdesign.kinematics.pcc`)
does, so one arc (kappa >= 0, phi, L) is fitted to it with its base fixed on {S}.

Fit
    Backbone samples are matched to arc points at equal arc-length
    fractions: the sample at fraction ``f = s / S`` of the link's own arc
    length ``S`` is compared with the arc's point at ``f L`` (a material
    point of a uniformly stretched section).  The least-squares objective is
    the arc-length integral of the squared distance (trapezoid weights on
    ``f``), minimized over ``(kappa L0 cos phi, kappa L0 sin phi, L / L0)``
    with ``L0 = S``: smooth and dimensionless, no singularity at kappa = 0.
Errors reported
    Distances between matched points (max and arc-length RMS, mm; the
    distance to the nearest arc point is never larger), the tip position
    error (mm), and at the tip: the angle between the arc's end tangent and
    T(q, l_e), and the full rotation angle between the arc's end frame and
    F(q, l_e), both in {S}.  The arc's end frame is {S} carried along the arc
    without twist, so the rotation error also holds the backbone's twist
    relative to that transport (with ``frames: frenet``, the Frenet roll).
Chambers
    Three chambers at ``d`` mm from the backbone at 90, 210, 330 degrees
    from {S}'s N axis (x), as :func:`pcc.lengths_from_arcs`; their strain is
    relative to the same link's fit at q = 0.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from softdesign.errors import ConfigError, FitError
from softdesign.geometry.frames import FramedSpline
from softdesign.geometry.se3 import axis_angle_from_rotation, inverse_pose
from softdesign.kinematics import pcc
from softdesign.kinematics.links import LinkChain
from softdesign.types import FloatArray, Points, Pose

#: Stated in every ``pcc design`` output.
DESIGN_CONVENTION = (
    "Per q and link, one constant-curvature arc starting at the link's start frame {S} = F(q, l_start) = [N B T c], "
    "tangent to T; phi (rad) is measured from N towards B, the arc bends towards phi; chambers at 90, 210, 330 degrees "
    "from N, d mm from the backbone (Zou et al.); chamber_strain = l_j(q) / l_j(0) - 1 "
    "against the same link's arc at q = 0. "
    "The arc is the least-squares fit of the backbone samples matched at equal arc-length fractions "
    "(trapezoid weights); "
    "backbone_max_mm and backbone_rms_mm are distances between matched points; tip_error_mm is the distance between "
    "the arc's tip and c(q, l_end); tangent_error_rad is the angle between the arc's end tangent and T(q, l_end); "
    "rotation_error_rad is the rotation angle between the arc's end frame (no twist) and F(q, l_end), both in {S}; "
    "worst is the link with the largest backbone_max_mm"
)
#: The figures of how far an arc misses the design (JSON keys), also those of each q's worst link.
ERROR_KEYS = ("backbone_max_mm", "backbone_rms_mm", "tip_error_mm", "tangent_error_rad", "rotation_error_rad")
#: Below this bending angle (rad) the bending plane is rounding noise: reported straight (kappa = 0, phi = 0).
STRAIGHT_THETA_RAD = 1e-9
#: Stopping tolerances of the dimensionless least-squares problem (relative change of x, cost, gradient).
SOLVER_TOL = 1e-12
#: Fewest backbone samples per link: three parameters need at least two points besides the base.
MIN_SAMPLES = 3


class BestArc(NamedTuple):
    """One section's arc as scalars (:class:`pcc.ArcParameters` holds arrays of them)."""

    kappa: float  #: curvature, 1/mm, >= 0
    phi: float  #: bending-plane angle, rad, in (-pi, pi]; 0 when straight
    length: float  #: arc length L, mm
    theta: float  #: bending angle kappa L, rad


class ArcFit(NamedTuple):
    """One link's best arc and how far it misses the backbone (mm, rad, 1/mm)."""

    kappa: float  #: curvature, 1/mm, >= 0
    phi: float  #: bending-plane angle from N towards B of {S}, rad, in (-pi, pi]; 0 when straight
    length: float  #: arc length L, mm
    theta: float  #: bending angle kappa L, rad
    backbone_max_mm: float  #: largest distance between matched points
    backbone_rms_mm: float  #: arc-length RMS distance between matched points
    tip_error_mm: float  #: |arc tip - c(q, l_e)|
    tangent_error_rad: float  #: angle between the arc's end tangent and T(q, l_e)
    rotation_error_rad: float  #: rotation angle between the arc's end frame and F(q, l_e)


def trapezoid_weights(fractions: npt.ArrayLike) -> FloatArray:
    """Trapezoid weights (n,) of samples at increasing ``fractions`` (n,) of [0, 1]; they sum to 1."""
    f = np.asarray(fractions, float)
    steps = np.diff(f)
    weights = np.zeros(len(f))
    weights[:-1] += 0.5 * steps
    weights[1:] += 0.5 * steps
    return weights


def arc_points(kappa: float, phi: float, length: float, fractions: npt.ArrayLike) -> Points:
    """Points (n, 3) mm of an arc at ``fractions`` (n,) of its length, in its base frame (pcc's model)."""
    return pcc.tip_position_from_arc(kappa, phi, length * np.asarray(fractions, float))


def _checked_backbone(points: npt.ArrayLike, fractions: npt.ArrayLike) -> tuple[Points, FloatArray]:
    points, fractions = np.asarray(points, float), np.asarray(fractions, float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < MIN_SAMPLES or fractions.shape != (len(points),):
        raise ConfigError(
            f"pcc fit: expected points (n, 3) and fractions (n,) with n >= {MIN_SAMPLES}; "
            f"got shapes {points.shape} and {fractions.shape}"
        )
    if not (
        np.all(np.isfinite(points))
        and fractions[0] == 0.0 and fractions[-1] == 1.0 and np.all(np.diff(fractions) > 0)
    ):
        raise ConfigError("pcc fit: fractions must rise strictly from 0 to 1 and points must be finite")
    return points, fractions


def fit_arc(points: npt.ArrayLike, fractions: npt.ArrayLike, length_scale: float) -> BestArc:
    """Least-squares arc from the origin, tangent to z, through backbone points matched by fraction.

    Parameters
    ----------
    points : (n, 3) float, mm
        Backbone in the arc's base frame, proximal first (``points[0]`` at the origin).
    fractions : (n,) float
        Arc-length fraction of each point along the backbone, 0 first, 1 last.
    length_scale : float, mm, > 0
        The backbone's arc length ``S``: the start value of L and the unit of the solver.

    Returns
    -------
    BestArc
        Scalars ``kappa`` (1/mm, >= 0), ``phi`` (rad), ``length`` (mm), ``theta`` (rad).

    Raises
    ------
    FitError
        The solver stopped without converging, or the best length is not > 0.
    """
    points, fractions = _checked_backbone(points, fractions)
    scale = float(length_scale)
    if not (math.isfinite(scale) and scale > 0.0):
        raise ConfigError(f"pcc fit: the backbone's arc length must be finite and > 0 mm, got {scale}")
    target = points / scale
    root_w = np.sqrt(trapezoid_weights(fractions))[:, None]

    def residual(x: FloatArray) -> FloatArray:
        # in units of S: x = (kappa S cos phi, kappa S sin phi, L / S)
        kappa_s, phi = np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])
        return (root_w * (arc_points(kappa_s, phi, x[2], fractions) - target)).ravel()

    # start from the arc through the tip: its chord makes half the bending angle with z
    tip = target[-1]
    theta0, phi0 = 2.0 * np.arctan2(np.hypot(tip[0], tip[1]), tip[2]), np.arctan2(tip[1], tip[0])
    x0 = np.array([theta0 * np.cos(phi0), theta0 * np.sin(phi0), 1.0])
    found = least_squares(residual, x0, jac="3-point", xtol=SOLVER_TOL, ftol=SOLVER_TOL, gtol=SOLVER_TOL)
    if not found.success or not found.x[2] > 0.0:
        raise FitError(
            f"pcc fit: no best arc found ({found.message}; length ratio {found.x[2]:.3g}); "
            "the backbone may fold back on itself: use more links"
        )
    theta_s, length = float(np.hypot(found.x[0], found.x[1])), float(found.x[2] * scale)
    if theta_s * found.x[2] < STRAIGHT_THETA_RAD:
        return BestArc(0.0, 0.0, length, 0.0)
    kappa = theta_s / scale
    return BestArc(kappa, float(np.arctan2(found.x[1], found.x[0])), length, kappa * length)


def _angle_between(a: FloatArray, b: FloatArray) -> float:
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))


def fit_link(poses: npt.ArrayLike, arc_length: npt.ArrayLike) -> ArcFit:
    """Best arc of one link and its errors, from the design's frames along the link.

    Parameters
    ----------
    poses : (n, 4, 4) float
        F(q, l) at n samples from l_s (first, the link's {S}) to l_e (last), any common frame, mm.
    arc_length : (n,) float, mm
        Arc length of each sample from the first, strictly increasing.

    Returns
    -------
    ArcFit
    """
    poses, arc_length = np.asarray(poses, float), np.asarray(arc_length, float)
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or arc_length.shape != (len(poses),):
        raise ConfigError(
            f"pcc fit: expected poses (n, 4, 4) and arc lengths (n,); got {poses.shape}, {arc_length.shape}"
        )
    in_start = inverse_pose(poses[0]) @ poses
    points, end2start = in_start[:, :3, 3], in_start[-1]
    total = float(arc_length[-1] - arc_length[0])
    fractions = (arc_length - arc_length[0]) / total
    fractions[-1] = 1.0
    arc = fit_arc(points, fractions, total)
    distance = np.linalg.norm(arc_points(arc.kappa, arc.phi, arc.length, fractions) - points, axis=1)
    arc_end = pcc.transform_from_arc(arc.kappa, arc.phi, arc.length)
    _, rotation_error = axis_angle_from_rotation(arc_end[:3, :3].T @ end2start[:3, :3])
    return ArcFit(
        arc.kappa,
        arc.phi,
        arc.length,
        arc.theta,
        backbone_max_mm=float(distance.max()),
        backbone_rms_mm=float(np.sqrt(trapezoid_weights(fractions) @ distance**2)),
        tip_error_mm=float(np.linalg.norm(arc_end[:3, 3] - end2start[:3, 3])),
        tangent_error_rad=_angle_between(arc_end[:3, 2], end2start[:3, 2]),
        rotation_error_rad=float(rotation_error),
    )


@dataclass(frozen=True)
class LinkDesign:
    """One link at one q: its l range, best arc and the chambers it needs (mm)."""

    index: int
    l_start: float
    l_end: float
    arc: ArcFit
    chamber_lengths: FloatArray  #: (3,) mm, chambers at 90, 210, 330 degrees
    chamber_strain: FloatArray  #: (3,) l_j(q) / l_j(0) - 1


@dataclass(frozen=True)
class PoseDesign:
    """Every link at one q, and the index of the link whose backbone the arc misses most."""

    q: float
    links: tuple[LinkDesign, ...]

    @property
    def worst(self) -> LinkDesign:
        """The link with the largest backbone deviation."""
        return max(self.links, key=lambda link: link.arc.backbone_max_mm)


def sample_link(chain: LinkChain, curve: FramedSpline, link: int, samples: int) -> tuple[Pose, FloatArray]:
    """Poses F(q, l) (samples, 4, 4) and arc length from l_s (samples,) mm along one link.

    ``curve`` is ``chain.shape.curve_at(q)``; the samples are equally spaced in l, both ends included.
    """
    l = np.linspace(chain.breaks[link], chain.breaks[link + 1], int(samples))
    s = curve.curve.arc_length(l)
    return curve.poses(l), s - s[0]


def fit_links(chain: LinkChain, q: float, samples: int) -> list[ArcFit]:
    """The best arc of every link of ``chain`` at one q (every link at the same q)."""
    curve = chain.shape.curve_at(float(q))
    out = []
    for j in range(chain.count):
        try:
            out.append(fit_link(*sample_link(chain, curve, j, samples)))
        except FitError as err:
            raise FitError(f"q = {q:g}, link {j}: {err}") from err
    return out


@dataclass(frozen=True)
class PccDesign:
    """One PCC section per link at every requested q, and what a designer must know about it."""

    d: FloatArray  #: (n_links,) mm, chamber distance from the backbone
    poses: tuple[PoseDesign, ...]
    notes: tuple[str, ...]  #: chambers that would need a length <= 0 (kappa d >= 1), at q = 0 or a requested q


def design_sections(
    chain: LinkChain, q_values: Sequence[float] | FloatArray, d: npt.ArrayLike, samples: int = 201
) -> PccDesign:
    """One PCC section per link at every q: best arcs, chamber lengths and strain against q = 0.

    Parameters
    ----------
    chain : the design's links (breaks in normalized l) on its blended shape
    q_values : (m,) morph parameters in [0, 1]
    d : float or (n_links,) float, mm, > 0 -- chamber distance from the backbone, per link
    samples : backbone samples per link, >= 3

    Returns
    -------
    PccDesign
        ``poses`` in the order of ``q_values``; the q = 0 fit is always made (the strain's reference).
    """
    if isinstance(samples, bool) or int(samples) != samples or samples < MIN_SAMPLES:
        raise ConfigError(f"pcc design: backbone samples per link must be an integer >= {MIN_SAMPLES}, got {samples}")
    d = np.broadcast_to(pcc.check_spacing(d), (chain.count,)).copy()
    zero = fit_links(chain, 0.0, samples)
    reference = _chamber_lengths(zero, d)
    notes = [] if 0.0 in list(q_values) else _infeasible(0.0, zero, reference, d)
    poses = []
    for q in q_values:
        fits = zero if q == 0.0 else fit_links(chain, float(q), samples)
        lengths = _chamber_lengths(fits, d)
        notes += _infeasible(float(q), fits, lengths, d)
        links = tuple(
            LinkDesign(j, float(chain.breaks[j]), float(chain.breaks[j + 1]), fits[j], lengths[j],
                       lengths[j] / reference[j] - 1.0)
            for j in range(chain.count)
        )
        poses.append(PoseDesign(float(q), links))
    return PccDesign(d, tuple(poses), tuple(notes))


def _chamber_lengths(fits: list[ArcFit], d: FloatArray) -> FloatArray:
    """(n_links, 3) mm; values <= 0 where kappa d >= 1 are kept and named by :func:`_infeasible`."""
    kappa, phi, length = (np.array([getattr(f, name) for f in fits]) for name in ("kappa", "phi", "length"))
    return pcc.lengths_from_arcs(kappa, phi, length, d)


def _infeasible(q: float, fits: list[ArcFit], lengths: FloatArray, d: FloatArray) -> list[str]:
    """One sentence per link whose chamber lengths are not all > 0."""
    notes = []
    for j, fit in enumerate(fits):
        bad = [k + 1 for k in range(3) if not lengths[j, k] > 0.0]
        if bad:
            notes.append(
                f"q = {q:g}, link {j}: chamber(s) {bad} would be <= 0 mm long (kappa d = {fit.kappa * d[j]:.3g} >= 1): "
                f"with d = {d[j]:g} mm a PCC section cannot bend this far; use d < 1/kappa = {1.0 / fit.kappa:.3g} mm "
                "for this link, or more links"
            )
    return notes


def link_dict(link: LinkDesign) -> dict:
    """One link at one q as JSON (documented keys, in order)."""
    a = link.arc
    return {
        "index": link.index,
        "l_start": link.l_start,
        "l_end": link.l_end,
        "kappa": a.kappa,
        "phi": a.phi,
        "length": a.length,
        "theta": a.theta,
        "dh": pcc.dh_rows(a.kappa, a.phi, a.length),
        "chamber_lengths": link.chamber_lengths.tolist(),
        "chamber_strain": link.chamber_strain.tolist(),
        "backbone_max_mm": a.backbone_max_mm,
        "backbone_rms_mm": a.backbone_rms_mm,
        "tip_error_mm": a.tip_error_mm,
        "tangent_error_rad": a.tangent_error_rad,
        "rotation_error_rad": a.rotation_error_rad,
    }


def design_document(design: PccDesign) -> dict:
    """The JSON object of ``softdesign pcc design``: d, per-q links and worst link, the convention."""
    poses = []
    for pose in design.poses:
        worst = link_dict(pose.worst)
        summary = {"index": worst["index"], **{k: worst[k] for k in ERROR_KEYS}}
        poses.append({"q": pose.q, "links": [link_dict(link) for link in pose.links], "worst": summary})
    return {"d": design.d.tolist(), "poses": poses, "convention": DESIGN_CONVENTION}
