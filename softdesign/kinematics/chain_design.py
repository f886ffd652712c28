"""Design a chain of constant-curvature sections that, composed from the base frame, follows a centerline.

A multi-section actuator is built as a chain (seed 003's improved D-H): section
i + 1 starts where section i's tip ends.  This module chooses the number of
sections and each one's curvature vector ``w`` (:mod:`pcc_chain`) and length
L so that the *composed* chain stays within a tolerance of the target
centerline everywhere, the tip included.  No I/O.

Method (``METHOD``)
    For k = 1, 2, ... sections, in turn:

    1. starts: the target's curvature vector in its rotation-minimizing frames
       (constant along an arc of a PCC chain) split into k constant pieces by
       an exact dynamic programme (least squares, pieces >= the shortest
       link), each piece's mean curvature and length a section; and the
       least-squares chain of k - 1 sections (step 2) with its worst section
       split in two halves of the same arc (the same shape);
    2. a joint least squares over every section's (wx, wy, L) at once: the
       vectors from the target's samples to their closest points on the whole
       chain (exact, :func:`pcc_chain.feet_on_chain`), and the tip's position
       and tangent against the target's;
    3. a minimax refinement: Lawson's reweighting of the same residuals, each
       round kept only if the largest distance went down.

    The breaks fall where the chain's joints are, by arc-length fraction:
    ``l_i = (L_1 + ... + L_i) / (L_1 + ... + L_k)`` in normalized l of the
    target, so the target's part [l_i, l_i+1] is carried onto section i by
    arc-length fraction.  Each k's chain is measured (below); the first k
    whose chain meets every bound is the design; with none up to
    ``max_links``, the chain with the smallest worst figure found.
Measured, never estimated
    ``chain_max_deviation_mm`` is the largest true distance both ways: every
    target sample to the chain (closed form per arc), and every point of the
    chain sampled at most ``CHAIN_STEP_MM`` apart to the target's dense
    polyline (exact point-to-polyline distance).  The tip error is the
    distance between the chain's tip and the target's end and the angle
    between their tangents.
What is guaranteed
    The reported figures are measurements of the returned chain; ``meets``
    is true only when they are within the bounds.  Looser bounds never give
    more sections (so a smaller tolerance never gives fewer): the starts and
    least-squares chain of every k depend on no bound; the minimax refinement
    runs when that chain's worst residual is within ``MINIMAX_REACH`` times the
    tolerance (a rule that looser bounds only widen), and its chain is taken
    when it meets the bounds or improves on a least-squares chain that does
    not, so a k that meets some bounds meets every looser ones.  A target
    made of k arcs (each at least the shortest link) starts on its joints:
    the dynamic programme finds them, and the tests show k sections found.
What is not
    Fewest sections is not proven: a k whose search missed the bounds is not
    shown to have no chain within them (the problem is not convex).  The
    minimax refinement is a local one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.optimize import least_squares

from softdesign.errors import ConfigError
from softdesign.kinematics.pcc_chain import (
    dense_chain_points,
    distances_to_polyline,
    feet_on_chain,
    section_poses,
)
from softdesign.types import FloatArray, Frames, Points, Pose

METHOD = ("k = 1, 2, ...: curvature-segmentation and split starts, joint least squares of the composed chain "
          "over (wx, wy, L) of every section, Lawson minimax refinement; fewest k whose measured chain meets the "
          "bounds")
#: Largest spacing of the chain's points measured against the target, mm.
CHAIN_STEP_MM = 0.1
#: Target samples the optimisation works on (every j-th sample, the last kept); the measurement uses all.
WORK_SAMPLES = 240
#: Weight of the tip position's residual against a sample's (the tip error is a bound of its own).
TIP_WEIGHT = 3.0
#: The tip tangent's residual is the tangent difference times this length, mm (1 degree ~ 0.26 mm): on the demo at
#: T = 1 mm it brings the tip from 4.1 to 1.5 degrees off with the same sections (5 mm did not; 30 mm made the
#: aorta at T = 0.5 mm need one section more).
TANGENT_LENGTH_MM = 15.0
#: Lawson reweighting rounds of the minimax refinement.
MINIMAX_ROUNDS = 8
#: Most residual evaluations of one least-squares solve.
MAX_EVALUATIONS = 60
#: Most residual evaluations of one minimax round.
MINIMAX_EVALUATIONS = 15
#: A k's least-squares chain is refined towards minimax only when its worst distance is within this factor of the
#: tolerance (the refinement lowers it by far less): a rule that a smaller tolerance can only make stricter.
MINIMAX_REACH = 2.0
#: Relative finite-difference step of the Jacobian.
FD_STEP = 1e-7


@dataclass(frozen=True)
class ChainTarget:
    """The centerline to follow.

    Attributes
    ----------
    points : (n, 3) mm, samples proximal first; ``frames`` (n, 3, 3) rotation-minimizing, columns (N, B, T)
    arc_length : (n,) mm from 0, strictly rising
    polyline : (p, 3) mm, a dense sampling of the same centerline (the chain is measured against it)
    """

    points: Points
    frames: Frames
    arc_length: FloatArray
    polyline: Points


@dataclass(frozen=True)
class ChainOptions:
    """Bounds: deviation and tip (mm), tip angle (deg, None: unbounded), shortest section (mm), most sections."""

    tolerance_mm: float
    tip_tolerance_mm: float
    tip_tolerance_deg: float | None
    min_link_mm: float
    max_links: int


@dataclass(frozen=True)
class ChainDesign:
    """A measured chain.

    Attributes
    ----------
    base2world : (4, 4) where section 1 starts; ``tips`` (k, 4, 4) each section's tip frame in the world
    w : (k, 2) 1/mm curvature vectors;  length : (k,) mm;  breaks : (k + 1,) normalized l of the target
    section_deviation_mm : (k,) the largest distance over each section (both ways)
    target_deviation_mm : (n,) each target sample's distance to the chain
    chain_max_deviation_mm, tip_error_mm, tip_error_deg : the measurements
    meets : every bound met;  tried : (k, worst of deviation and tip mm) of every k searched
    """

    base2world: Pose
    tips: Pose
    w: FloatArray
    length: FloatArray
    breaks: FloatArray
    section_deviation_mm: FloatArray
    target_deviation_mm: FloatArray
    chain_max_deviation_mm: float
    tip_error_mm: float
    tip_error_deg: float
    meets: bool
    tried: tuple[tuple[int, float], ...]

    @property
    def worst_mm(self) -> float:
        """The larger of the chain's deviation and its tip error, mm: what each k's search minimises."""
        return max(self.chain_max_deviation_mm, self.tip_error_mm)


@dataclass(frozen=True)
class _Work:
    """What the optimisation uses: a subsample of the target, its end poses and curvature signal."""

    points: Points
    arc_length: FloatArray
    base: Pose
    tip: Pose
    curvature: FloatArray  # (m - 1, 2) 1/mm between consecutive work samples, in the first one's frame


def design_chain(target: ChainTarget, options: ChainOptions) -> ChainDesign:
    """The fewest sections (searched k = 1, 2, ...) whose composed chain meets the bounds; see the module docstring.

    Raises
    ------
    ConfigError
        Bad target arrays or options (names the option and the fix).
    """
    _check(target, options)
    work = _work(target)
    starts = _segmentations(work, options)
    tree = _tree(target.polyline)
    best: ChainDesign | None = None
    previous: ChainDesign | None = None
    tried: list[tuple[int, float]] = []
    for k in range(1, options.max_links + 1):
        pieces = starts[k]
        candidates = [] if pieces is None else [_arcs_from_pieces(work, pieces)]
        if previous is not None and (split := _split_worst(previous, options.min_link_mm)) is not None:
            candidates.append(split)
        if not candidates:
            break
        fits = [_solve(work, _packed(w, length), options.min_link_mm) for w, length in candidates]
        x = min(fits, key=lambda f: _worst(work, f))
        fitted = _measure(target, tree, work.base, *_unpacked(x))
        chosen = fitted
        if _worst(work, x) <= MINIMAX_REACH * options.tolerance_mm:
            refined = _measure(target, tree, work.base, *_unpacked(_minimax(work, x, options.min_link_mm)))
            # kept when it meets the bounds, or improves on a least-squares chain that does not: a chain that
            # meets them is never swapped for one that does not (see "What is guaranteed")
            if _meets(refined, options) or (not _meets(fitted, options) and refined.worst_mm < fitted.worst_mm):
                chosen = refined
        tried.append((k, chosen.worst_mm))
        if best is None or chosen.worst_mm < best.worst_mm:
            best = chosen
        if _meets(chosen, options):
            return _final(chosen, True, tried)
        previous = fitted  # the least-squares chain: the next k's split start depends on no bound
    assert best is not None  # k = 1 always has the whole target as one piece
    return _final(best, False, tried)


def _final(design: ChainDesign, meets: bool, tried: list[tuple[int, float]]) -> ChainDesign:
    return ChainDesign(design.base2world, design.tips, design.w, design.length, design.breaks,
                       design.section_deviation_mm, design.target_deviation_mm, design.chain_max_deviation_mm,
                       design.tip_error_mm, design.tip_error_deg, meets, tuple(tried))


def _meets(design: ChainDesign, options: ChainOptions) -> bool:
    angle_ok = options.tip_tolerance_deg is None or design.tip_error_deg <= options.tip_tolerance_deg
    return (design.chain_max_deviation_mm <= options.tolerance_mm and design.tip_error_mm <= options.tip_tolerance_mm
            and angle_ok)


def _check(target: ChainTarget, options: ChainOptions) -> None:
    n = len(target.points)
    polyline_ok = target.polyline.ndim == 2 and target.polyline.shape[1] == 3 and len(target.polyline) >= 2
    shapes_ok = (target.points.shape == (n, 3) and target.frames.shape == (n, 3, 3)
                 and target.arc_length.shape == (n,) and n >= 2 and polyline_ok)
    if not shapes_ok:
        raise ConfigError(f"design: expected points (n, 3), frames (n, 3, 3), arc length (n,), n >= 2 and a polyline "
                          f"(p, 3); got {target.points.shape}, {target.frames.shape}, {target.arc_length.shape}, "
                          f"{target.polyline.shape}")
    if not (target.arc_length[0] == 0.0 and np.all(np.diff(target.arc_length) > 0.0)):
        raise ConfigError("design: the target's arc length must rise strictly from 0")
    total = float(target.arc_length[-1])
    for name, value in (("tolerance_mm", options.tolerance_mm), ("tip_tolerance_mm", options.tip_tolerance_mm),
                        ("min_link_mm", options.min_link_mm)):
        if not (np.isfinite(value) and value > 0.0):
            raise ConfigError(f"design.{name} must be a finite number > 0 mm, got {value}")
    if options.tip_tolerance_deg is not None and not (np.isfinite(options.tip_tolerance_deg)
                                                      and options.tip_tolerance_deg > 0.0):
        raise ConfigError(f"design.tip_tolerance_deg must be a finite number > 0, got {options.tip_tolerance_deg}")
    if options.min_link_mm > total:
        raise ConfigError(f"design.min_link_mm {options.min_link_mm:g} is longer than the centerline "
                          f"({total:.4g} mm); give at most {total:.4g}")
    if int(options.max_links) != options.max_links or options.max_links < 1:
        raise ConfigError(f"design.max_links must be an integer >= 1, got {options.max_links!r}")


def _pose(frame: FloatArray, origin: FloatArray) -> Pose:
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = frame, origin
    return pose


def _work(target: ChainTarget) -> _Work:
    n = len(target.points)
    stride = max(1, int(np.ceil((n - 1) / (WORK_SAMPLES - 1))))
    index = np.unique(np.concatenate([np.arange(0, n, stride), [n - 1]]))
    frames, s = target.frames[index], target.arc_length[index]
    relative = np.einsum("mji,mjk->mik", frames[:-1], frames[1:])  # frame j+1 in frame j
    omega_x = 0.5 * (relative[:, 2, 1] - relative[:, 1, 2])
    omega_y = 0.5 * (relative[:, 0, 2] - relative[:, 2, 0])
    curvature = np.stack([omega_y, -omega_x], axis=1) / np.diff(s)[:, None]  # w = (kx, ky), omega = (-ky, kx, 0)
    return _Work(target.points[index], s, _pose(target.frames[0], target.points[0]),
                 _pose(target.frames[-1], target.points[-1]), curvature)


def _segmentations(work: _Work, options: ChainOptions) -> list[list[int] | None]:
    """Per k (index), the work-sample breaks of the best k-piece constant fit of the curvature signal, or None."""
    h = np.diff(work.arc_length)
    s1 = np.concatenate([[np.zeros(2)], np.cumsum(work.curvature * h[:, None], axis=0)])
    s2 = np.concatenate([[0.0], np.cumsum(np.sum(work.curvature**2, axis=1) * h)])
    s = work.arc_length
    with np.errstate(divide="ignore", invalid="ignore"):
        span = s[None, :] - s[:, None]
        cost = (s2[None, :] - s2[:, None]) - np.sum((s1[None, :, :] - s1[:, None, :]) ** 2, axis=2) / span
    cost = np.where(span >= options.min_link_mm * (1.0 - 1e-9), np.maximum(cost, 0.0), np.inf)
    m = len(s)
    best = np.full(m, np.inf)
    best[0] = 0.0
    out: list[list[int] | None] = [None]
    parents: list[npt.NDArray[np.int64]] = []
    for _ in range(options.max_links):
        total = best[:, None] + cost
        parent = np.argmin(total, axis=0)
        best = total[parent, np.arange(m)]
        parents.append(parent)
        if not np.isfinite(best[-1]):
            out.append(None)
            continue
        breaks = [m - 1]
        for level in range(len(parents) - 1, -1, -1):
            breaks.append(int(parents[level][breaks[-1]]))
        out.append(breaks[::-1])
    return out


def _arcs_from_pieces(work: _Work, breaks: list[int]) -> tuple[FloatArray, FloatArray]:
    h = np.diff(work.arc_length)
    w, length = [], []
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        w.append(np.sum(work.curvature[a:b] * h[a:b, None], axis=0) / np.sum(h[a:b]))
        length.append(work.arc_length[b] - work.arc_length[a])
    return np.array(w), np.array(length)


def _split_worst(design: ChainDesign, min_link_mm: float) -> tuple[FloatArray, FloatArray] | None:
    """The same chain with its worst section (long enough) split into two halves of its arc."""
    splittable = design.length >= 2.0 * min_link_mm
    if not splittable.any():
        return None
    i = int(np.argmax(np.where(splittable, design.section_deviation_mm, -np.inf)))
    w = np.insert(design.w, i, design.w[i], axis=0)
    length = np.insert(design.length, i, 0.5 * design.length[i])
    length[i + 1] = 0.5 * design.length[i]
    return w, length


def _residuals(work: _Work, x: FloatArray, sections: npt.NDArray[np.int64] | None = None) -> FloatArray:
    """Residuals (B, 3 m + 6) of parameter rows x (B, 3 k): sample-to-chain vectors, tip position and tangent.

    With ``sections`` (m,) each sample is measured to that section only (the Jacobian's perturbed chains).
    """
    k = x.shape[1] // 3
    w, length = x[:, :2 * k].reshape(-1, k, 2), x[:, 2 * k:]
    bases, tips = section_poses(work.base, w, length)
    feet, _, _ = feet_on_chain(work.points, bases, w, length, sections)
    tip = tips[:, -1]
    parts = [(work.points - feet).reshape(len(x), -1), TIP_WEIGHT * (tip[:, :3, 3] - work.tip[:3, 3]),
             TANGENT_LENGTH_MM * (tip[:, :3, 2] - work.tip[:3, 2])]
    return np.concatenate(parts, axis=1)


def _packed(w: FloatArray, length: FloatArray) -> FloatArray:
    return np.concatenate([np.asarray(w, float).ravel(), np.asarray(length, float)])


def _unpacked(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    k = len(x) // 3
    return x[:2 * k].reshape(k, 2), x[2 * k:]


def _minimax(work: _Work, x: FloatArray, min_link_mm: float) -> FloatArray:
    """Lawson's reweighting of the least squares towards the smallest worst residual (rounds kept while it drops)."""
    weights = np.ones(len(work.points) + 2)
    worst = _worst(work, x)
    for _ in range(MINIMAX_ROUNDS):
        rows = np.linalg.norm(_residuals(work, x[None])[0].reshape(-1, 3), axis=1)
        weights = weights * rows / max(float(np.max(rows)), 1e-300)
        weights = np.maximum(weights / weights.max(), 1e-6)
        trial = _solve(work, x, min_link_mm, weights, MINIMAX_EVALUATIONS)
        trial_worst = _worst(work, trial)
        if trial_worst >= worst:
            break
        x, worst = trial, trial_worst
    return x


def _worst(work: _Work, x: FloatArray) -> float:
    rows = np.linalg.norm(_residuals(work, x[None])[0].reshape(-1, 3), axis=1)
    return float(max(rows[:-2].max(), rows[-2] / TIP_WEIGHT))


def _solve(work: _Work, x0: FloatArray, min_link_mm: float, weights: FloatArray | None = None,
           evaluations: int = MAX_EVALUATIONS) -> FloatArray:
    """Weighted least squares of :func:`_residuals` from ``x0``, every L >= ``min_link_mm``."""
    k = len(x0) // 3
    lower = np.concatenate([np.full(2 * k, -np.inf), np.full(k, min_link_mm)])
    scale = np.repeat(np.sqrt(np.ones(len(work.points) + 2) if weights is None else weights), 3)

    def fun(x: FloatArray) -> FloatArray:
        return scale * _residuals(work, x[None])[0]

    def jac(x: FloatArray) -> FloatArray:
        step = FD_STEP * np.maximum(np.abs(x), 1e-3)
        k = len(x) // 3
        bases, _ = section_poses(work.base, x[None, :2 * k].reshape(1, k, 2), x[None, 2 * k:])
        _, _, sections = feet_on_chain(work.points, bases, x[:2 * k].reshape(1, k, 2), x[None, 2 * k:])
        batch = np.vstack([x, x + np.diag(step)])
        values = scale * _residuals(work, batch, sections[0])
        return ((values[1:] - values[0]) / step[:, None]).T

    found = least_squares(fun, np.maximum(x0, lower), jac=jac, bounds=(lower, np.inf), method="trf",
                          x_scale="jac", max_nfev=evaluations, xtol=1e-10, ftol=1e-10, gtol=1e-10)
    return np.asarray(found.x, float)


def _tree(polyline: Points) -> object:
    from scipy.spatial import cKDTree

    return cKDTree(polyline)


def _measure(target: ChainTarget, tree: object, base: Pose, w: FloatArray, length: FloatArray) -> ChainDesign:
    """Every figure of a chain, measured (see the module docstring)."""
    bases, tips = section_poses(base, w, length)
    _, to_chain, _ = feet_on_chain(target.points, bases, w, length)
    step = min(CHAIN_STEP_MM, float(np.min(length)) / 2.0)
    dense, s = dense_chain_points(base, w, length, step)
    to_target = distances_to_polyline(dense, target.polyline, tree)
    joints = np.concatenate([[0.0], np.cumsum(length)])
    breaks = joints / joints[-1]
    l_target = target.arc_length / target.arc_length[-1]
    per_section = np.empty(len(length))
    for i in range(len(length)):
        on_target = to_chain[(l_target >= breaks[i]) & (l_target <= breaks[i + 1])]
        on_chain = to_target[(s >= joints[i]) & (s <= joints[i + 1])]
        per_section[i] = max(on_target.max(initial=0.0), on_chain.max(initial=0.0))
    tip = tips[-1]
    tip_mm = float(np.linalg.norm(tip[:3, 3] - target.points[-1]))
    cosine = float(np.clip(tip[:3, 2] @ target.frames[-1][:, 2], -1.0, 1.0))
    tip_deg = float(np.degrees(np.arccos(cosine)))
    deviation = float(max(to_chain.max(), to_target.max()))
    return ChainDesign(np.asarray(base, float), tips, w, length, breaks, per_section, to_chain, deviation,
                       tip_mm, tip_deg, False, ())
