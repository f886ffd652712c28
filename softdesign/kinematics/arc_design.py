"""Link design: the fewest constant-curvature arcs that stay within a tolerance of a centerline.

Seed 000 names "automated design of multi-link soft robots from patient-specific
data" as its next step; a three-chamber (or three-cable) section bends into one
constant-curvature arc (seed 003), so a PCC actuator reaches the patient's
shape only where every link is close to one arc.  This module chooses the
links; it has no I/O.

One link's arc
    A link from sample ``i`` to sample ``j`` is expressed in its start frame
    F(l_i) = [N B T c] (points ``p``, mm, x along N, y along B, z along T).
    Its arc starts at the origin tangent to z (seed 003's section in its base
    frame): curvature ``kappa`` (1/mm), bending plane ``phi`` (rad, from N
    towards B, the arc bends towards it), length ``L`` (mm).  Every point of
    such an arc satisfies ``p_xy = w |p|^2 / 2`` exactly, with ``w = kappa
    (cos phi, sin phi)`` the curvature vector, so the fit is the linear least
    squares ``w = sum(s_k q_k) / sum(s_k^2)``, ``s_k = |p_k|^2 / 2``, ``q_k =
    p_k,xy``.  Its residual ``q_k - w s_k`` is, across the bending plane,
    exactly the point's distance from that plane, and in the plane the
    algebraic distance to the circle, which equals the true radial distance
    to first order (the ratio is ``2 / (1 + |1 - kappa p|)``).  The sums are
    prefix sums along the centerline, so one start gives the arcs of every
    end at once.  ``L`` puts the arc's end at the foot of the link's last
    point on the circle (the angle unwrapped next to kappa times the link's
    arc length), so the arc ends where the link ends.
Deviation
    The true distance from each sample of the link to the arc (not to its
    circle: a foot beyond an end of the arc is replaced by that end), the
    maximum over the link's samples ``i..j`` (mm).  This differs from
    :mod:`pcc_fit` (``pcc design``), which matches points at equal
    arc-length fractions: a matched-point distance is never smaller.
Optimality
    :func:`segment` is exact over the candidate breaks (the samples) for the
    per-link cost above, the deviation of that link's fitted arc: no other
    choice of breaks among the samples gives fewer links within the
    tolerance, and among those with the fewest links none has a smaller
    worst deviation.  It is a dynamic programme on prefixes ordered
    lexicographically by (links, worst deviation); the order is preserved
    by appending a link (count + 1, max(worst, cost)), so the best prefix
    ending at each sample extends to the best segmentation.  The arc per
    link is the least-squares arc above, not the minimax arc: a link's
    reported deviation is a true upper bound, and a minimax arc could only
    lower it.
Chain
    The arcs are composed from the base frame by seed 003's improved D-H
    (Table 1, :func:`pcc.dh_table_from_arc`), each section's base frame the
    previous section's tip frame; the tip error is against the centerline's
    own tip pose inv(F(0)) F(1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError
from softdesign.geometry.se3 import axis_angle_from_rotation
from softdesign.kinematics import pcc
from softdesign.types import FloatArray, Frames, Points

#: Below this bending angle (rad) a link's bending plane is rounding noise: reported straight (phi = 0).
STRAIGHT_THETA_RAD = 1e-9
#: Most samples (candidate breaks) of a design: the deviations cost ~n^3/3 point-to-arc distances.
MAX_SAMPLES = 1201
#: Relative slack on the shortest link, so that rounding of arc lengths never drops a link of exactly M mm.
LENGTH_RTOL = 1e-9


@dataclass(frozen=True)
class DesignOptions:
    """What a design must meet.

    Attributes
    ----------
    tolerance_mm : largest deviation of a link from its arc, mm, > 0
    min_link_mm : shortest link, mm, > 0
    max_links : most links, >= 1
    """

    tolerance_mm: float
    min_link_mm: float
    max_links: int


@dataclass(frozen=True)
class DesignedLink:
    """One link: samples i..j, its arc (1/mm, rad, mm) and its largest deviation from it (mm)."""

    start: int
    end: int
    kappa: float
    phi: float
    length: float
    theta: float
    max_deviation_mm: float


@dataclass(frozen=True)
class LinkDesign:
    """A segmentation: its links, worst deviation, whether it meets the tolerance, and the chained tip error."""

    links: tuple[DesignedLink, ...]
    worst_mm: float
    meets_tolerance: bool
    tip_error_mm: float
    tip_error_rad: float

    @property
    def break_indices(self) -> list[int]:
        """Sample indices of the breaks, first sample and last included."""
        return [self.links[0].start] + [link.end for link in self.links]


def check_centerline(
    points: npt.ArrayLike, frames: npt.ArrayLike, arc_length: npt.ArrayLike
) -> tuple[Points, Frames, FloatArray]:
    """Samples (n, 3) mm, frames (n, 3, 3) columns (N, B, T), arc length (n,) mm strictly rising from 0.

    Raises
    ------
    ConfigError
        Wrong shapes, fewer than 2 samples, non-finite values, or s not rising.
    """
    points, frames, s = (np.asarray(x, float) for x in (points, frames, arc_length))
    n = len(points)
    if points.shape != (n, 3) or frames.shape != (n, 3, 3) or s.shape != (n,) or n < 2:
        raise ConfigError(
            f"design: expected points (n, 3), frames (n, 3, 3), arc length (n,), n >= 2; "
            f"got {points.shape}, {frames.shape}, {s.shape}"
        )
    finite = all(np.all(np.isfinite(x)) for x in (points, frames, s))
    if not (finite and s[0] == 0.0 and np.all(np.diff(s) > 0)):
        raise ConfigError("design: points and frames must be finite and arc length must rise strictly from 0")
    return points, frames, s


def check_sample_count(arc_length: FloatArray) -> None:
    """ConfigError when a design would have more than MAX_SAMPLES candidate breaks (its cost grows as n^3)."""
    n = len(arc_length)
    if n > MAX_SAMPLES:
        raise ConfigError(
            f"design: {n} samples along the centerline, at most {MAX_SAMPLES} (the cost grows as n^3); "
            f"raise resample.spacing_mm to about {arc_length[-1] / (MAX_SAMPLES - 1):.3g} mm or more"
        )


def curvature_vectors(local: Points) -> FloatArray:
    """Least-squares curvature vector (m, 2), 1/mm, of the arc through local[0] and each later prefix.

    ``local`` (m, 3) mm are a link's samples in its start frame, ``local[0]`` at the
    origin; row ``e`` is the fit to ``local[:e + 1]`` (row 0 is zero: no point to fit).
    """
    s = 0.5 * np.einsum("ij,ij->i", local, local)
    s2 = np.cumsum(s * s)
    g = np.cumsum(s[:, None] * local[:, :2], axis=0)
    out = np.zeros_like(g)
    np.divide(g, s2[:, None], out=out, where=s2[:, None] > 0.0)
    return out


def arc_lengths_to_feet(w: FloatArray, ends: Points, link_length: FloatArray) -> FloatArray:
    """Arc length (m,) mm from the start to the foot of each end point (m, 3) on its circle (curvature vector w (m, 2)).

    The foot's angle is unwrapped to the turn nearest kappa times the link's arc length (m,) mm.
    """
    kappa = np.hypot(w[:, 0], w[:, 1])
    u = np.einsum("ij,ij->i", w, ends[:, :2])  # kappa times the in-plane offset towards the centre
    angle = np.arctan2(kappa * ends[:, 2], 1.0 - u)
    turns = np.round((kappa * link_length - angle) / (2.0 * np.pi))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(kappa > 0.0, (angle + 2.0 * np.pi * turns) / kappa, ends[:, 2])


def distances_to_arcs(local: Points, w: FloatArray, length: FloatArray) -> FloatArray:
    """True distance (m, k) mm from each point (k, 3) to each arc (curvature vector w (m, 2), length (m,) mm).

    Arcs start at the origin tangent to z (see the module docstring).  In the bending plane the
    radial distance is ``e / (1 + sqrt(1 + kappa e))`` with ``e = kappa (u^2 + z^2) - 2 u`` (u towards
    the centre), which has no 1/kappa and is exact for a straight arc (``-u``).
    """
    kappa = np.hypot(w[:, 0], w[:, 1])
    safe = np.where(kappa > 0.0, kappa, 1.0)
    m = np.where(kappa[:, None] > 0.0, w / safe[:, None], [1.0, 0.0])  # unit bending direction (m, 2)
    u = m @ local[:, :2].T  # towards the centre, in the bending plane
    h = (m @ np.array([[0.0, 1.0], [-1.0, 0.0]])) @ local[:, :2].T  # across the bending plane: my x - mx y
    z = local[:, 2]
    r2 = np.einsum("ij,ij->i", local, local)
    k = kappa[:, None]
    e = k * (r2 - h * h) - 2.0 * u
    radial = e / (1.0 + np.sqrt(np.maximum(1.0 + k * e, 0.0)))
    foot2 = radial * radial + h * h
    theta_end = (kappa * length)[:, None]
    angle = np.arctan2(k * z, 1.0 - k * u)
    angle += 2.0 * np.pi * np.round((0.5 * theta_end - angle) / (2.0 * np.pi))  # the turn nearest the arc's middle
    along = np.where(k > 0.0, angle / safe[:, None], z)
    inside = (along >= 0.0) & (along <= length[:, None])
    tips = pcc.tip_position_from_arc(kappa, np.arctan2(m[:, 1], m[:, 0]), length)
    to_tip2 = r2 - 2.0 * (tips @ local.T) + np.einsum("ij,ij->i", tips, tips)[:, None]
    return np.sqrt(np.where(inside, foot2, np.maximum(np.minimum(r2, to_tip2), 0.0)))


def _local(points: Points, frames: Frames, i: int) -> Points:
    """Samples i.. in the frame F(l_i), (n - i, 3) mm."""
    return (points[i:] - points[i]) @ frames[i]


def link_costs(
    points: npt.ArrayLike, frames: npt.ArrayLike, arc_length: npt.ArrayLike, min_link_mm: float
) -> FloatArray:
    """Deviation (n, n) mm of every link i -> j from its fitted arc; inf where j <= i or shorter than min_link_mm.

    Parameters
    ----------
    points : (n, 3) float, mm;  frames : (n, 3, 3) columns (N, B, T);  arc_length : (n,) float, mm
    min_link_mm : shortest link allowed, mm
    """
    points, frames, s = check_centerline(points, frames, arc_length)
    check_sample_count(s)
    n = len(points)
    cost = np.full((n, n), np.inf)
    shortest = min_link_mm * (1.0 - LENGTH_RTOL)
    for i in range(n - 1):
        local = _local(points, frames, i)
        first = int(np.searchsorted(s[i:] - s[i], shortest, side="left"))
        if first >= len(local):
            break
        first = max(first, 1)
        w = curvature_vectors(local)[first:]
        length = arc_lengths_to_feet(w, local[first:], s[i + first :] - s[i])
        dist = distances_to_arcs(local, w, length)  # (ends, points)
        beyond = np.arange(len(local))[None, :] > np.arange(first, len(local))[:, None]
        worst = np.where(beyond, 0.0, dist).max(axis=1)
        cost[i, i + first :] = np.where(length > 0.0, worst, np.inf)
    return cost


def fewest_links(cost: npt.ArrayLike, tolerance_mm: float) -> list[int] | None:
    """Breaks (sample indices, 0 and n - 1 included) of the fewest links within tolerance, then the smallest worst cost.

    Exact over the candidate breaks (see the module docstring); None when no segmentation is within tolerance.
    """
    cost = np.asarray(cost, float)
    n = len(cost)
    count = np.full(n, np.inf)
    worst = np.full(n, np.inf)
    previous = np.full(n, -1)
    count[0], worst[0] = 0.0, 0.0
    allowed = cost <= tolerance_mm
    for j in range(1, n):
        ok = allowed[:j, j] & np.isfinite(count[:j])
        if not ok.any():
            continue
        candidates = np.flatnonzero(ok)
        c = count[candidates] + 1.0
        wv = np.maximum(worst[candidates], cost[candidates, j])
        pick = candidates[np.lexsort((wv, c))[0]]  # fewest links first, then the smallest worst deviation
        count[j], worst[j], previous[j] = count[pick] + 1.0, max(worst[pick], cost[pick, j]), pick
    return None if not np.isfinite(count[-1]) else _walk_back(previous, n - 1)


def best_within(cost: npt.ArrayLike, max_links: int) -> list[int] | None:
    """Breaks of the smallest worst cost with at most ``max_links`` links (exact minimax over the candidates).

    None when no segmentation exists (every link would be shorter than the minimum).
    """
    cost = np.asarray(cost, float)
    n = len(cost)
    best = np.full(n, np.inf)
    best[0] = 0.0
    tables, parents = [], []
    for _ in range(int(max_links)):
        stacked = np.maximum(best[:, None], cost)  # (i, j): reach i, then link i -> j
        parent = np.argmin(stacked, axis=0)
        best = stacked[parent, np.arange(n)]  # inf at sample 0: a link moves forward
        tables.append(best.copy())
        parents.append(parent)
    finals = [table[-1] for table in tables]
    k = int(np.argmin(finals))  # fewest links among equal worst costs
    if not np.isfinite(finals[k]):
        return None
    out = [n - 1]
    for level in range(k, -1, -1):
        out.append(int(parents[level][out[-1]]))
    return out[::-1]


def _walk_back(previous: npt.NDArray[np.int_], last: int) -> list[int]:
    out = [last]
    while out[-1] != 0:
        out.append(int(previous[out[-1]]))
    return out[::-1]


def fit_link(points: npt.ArrayLike, frames: npt.ArrayLike, arc_length: npt.ArrayLike, i: int, j: int) -> DesignedLink:
    """The arc of one link i -> j (sample indices, i < j) and its largest deviation, as :func:`link_costs` fits it."""
    points, frames, s = check_centerline(points, frames, arc_length)
    local = _local(points, frames, i)[: j - i + 1]
    w = curvature_vectors(local)[-1:]
    length = arc_lengths_to_feet(w, local[-1:], s[j : j + 1] - s[i])
    deviation = float(distances_to_arcs(local, w, length).max())
    kappa, phi = float(np.hypot(*w[0])), float(np.arctan2(w[0, 1], w[0, 0]))
    if kappa * abs(length[0]) < STRAIGHT_THETA_RAD:
        kappa, phi = 0.0, 0.0
    return DesignedLink(i, j, kappa, phi, float(length[0]), kappa * float(length[0]), deviation)


def chain_tip_error(links: tuple[DesignedLink, ...], frames: Frames, points: Points) -> tuple[float, float]:
    """Position (mm) and rotation angle (rad) between the arcs' chained tip and the centerline's tip, in the base frame.

    The chain is seed 003's improved D-H: each link's Table 1 rows, links multiplied in order.
    """
    kappa, phi, length = (np.array([getattr(k, name) for k in links]) for name in ("kappa", "phi", "length"))
    sections = pcc.transform_from_dh_table(pcc.dh_table_from_arc(kappa, phi, length))
    tip = pcc.chain_transforms(sections)[-1]
    target_rotation = frames[0].T @ frames[-1]
    target_position = frames[0].T @ (points[-1] - points[0])
    _, angle = axis_angle_from_rotation(tip[:3, :3].T @ target_rotation)
    return float(np.linalg.norm(tip[:3, 3] - target_position)), float(angle)


def design_links(
    points: npt.ArrayLike, frames: npt.ArrayLike, arc_length: npt.ArrayLike, options: DesignOptions
) -> LinkDesign:
    """The fewest links within ``options.tolerance_mm`` of one arc each, or the best within ``max_links``.

    Parameters
    ----------
    points : (n, 3) float, mm -- centerline samples, proximal first (candidate breaks)
    frames : (n, 3, 3) float -- F at each sample, columns (N, B, T)
    arc_length : (n,) float, mm -- from the first sample, strictly rising
    options : tolerance, shortest link, most links

    Returns
    -------
    LinkDesign
        ``meets_tolerance`` False when no segmentation of at most ``max_links`` links of at least
        ``min_link_mm`` meets the tolerance: then the links are the exact minimax segmentation with
        at most ``max_links`` links.

    Raises
    ------
    ConfigError
        Bad options (tolerance or shortest link not > 0, max_links < 1, a shortest link longer than the centerline).
    """
    points, frames, s = check_centerline(points, frames, arc_length)
    check_sample_count(s)
    _check_options(options, float(s[-1]))
    cost = link_costs(points, frames, s, options.min_link_mm)
    breaks = fewest_links(cost, options.tolerance_mm)
    meets = breaks is not None and len(breaks) - 1 <= options.max_links
    if not meets:
        breaks = best_within(cost, options.max_links)
    if breaks is None:  # unreachable after _check_options: one whole link is always allowed
        raise ConfigError("design: no segmentation exists; lower --min-link-mm")
    links = tuple(fit_link(points, frames, s, i, j) for i, j in zip(breaks[:-1], breaks[1:], strict=True))
    tip_mm, tip_rad = chain_tip_error(links, frames, points)
    worst = max(link.max_deviation_mm for link in links)
    return LinkDesign(links, worst, meets, tip_mm, tip_rad)


def _check_options(options: DesignOptions, total_mm: float) -> None:
    t, m, k = options.tolerance_mm, options.min_link_mm, options.max_links
    if not (np.isfinite(t) and t > 0.0):
        raise ConfigError(f"design: --tolerance-mm must be a finite number > 0 mm, got {t}")
    if not (np.isfinite(m) and m > 0.0):
        raise ConfigError(f"design: --min-link-mm must be a finite number > 0 mm, got {m}")
    if m > total_mm * (1.0 + LENGTH_RTOL):
        raise ConfigError(
            f"design: --min-link-mm {m:g} is longer than the centerline ({total_mm:.4g} mm); "
            f"give at most {total_mm:.4g}"
        )
    if isinstance(k, bool) or int(k) != k or k < 1:
        raise ConfigError(f"design: --max-links must be an integer >= 1, got {k!r}")
