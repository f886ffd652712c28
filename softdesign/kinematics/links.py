"""Links along the blended shape, their transforms S_T_E(q), and forward kinematics.

Breaks are values of l (normalized arc length of the final shape) in [0, 1].
Link j runs from l_s = breaks[j] to l_e = breaks[j + 1]; with
F(q, l) = [[N B T c], [0 0 0 1]] its transform is

    S_T_E^(j)(q) = inv(F(q, l_s)) @ F(q, l_e)        (end2start of link j)

Forward kinematics with one q per link (the seed's S_robot):

    tip2base(q_1..q_n)  = S_T_E^(1)(q_1) @ ... @ S_T_E^(n)(q_n)
    tip2world(q_1..q_n) = F(q_1, 0) @ tip2base(q_1..q_n)

``tip2base`` is expressed in the base frame {S} of link 1; ``tip2world`` in the
coordinates of the input files (F(q, 0) is the same for every q once the
initial shape is registered to the final shape's base).  With every q_j = q
the product telescopes to inv(F(q, 0)) @ F(q, 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError
from softdesign.geometry.blend import BlendedShape, BlendStats
from softdesign.geometry.frames import FramedSpline, poses_from_frames
from softdesign.geometry.se3 import inverse_pose
from softdesign.kinematics.poe import PoeSplit, poe_from_pose
from softdesign.types import FloatArray, FramedCurve, Pose

#: Shortest link allowed, as a fraction of the path (below it a link has no room for a surface fit).
MIN_LINK_FRACTION = 1e-3
#: With ``length_mm``, a remainder shorter than this fraction of a link joins the last full link.
REMAINDER_MERGE_FRACTION = 0.5


def link_breaks(
    total_length_mm: float,
    count: int | None = None,
    breaks: npt.ArrayLike | None = None,
    length_mm: float | None = None,
) -> FloatArray:
    """Link breaks in normalized l, (n_links + 1,), from exactly one rule.

    Parameters
    ----------
    total_length_mm : length of the final shape, mm
    count : n equal links
    breaks : explicit breaks, strictly increasing from 0 to 1
    length_mm : links of this length from l = 0; the remainder forms a last, shorter
        link if it is at least half a link, else it lengthens the last full link

    Raises
    ------
    ConfigError
        None or several rules, or invalid values (links shorter than 0.1 % of the path).
    """
    given = [name for name, value in (("count", count), ("breaks", breaks), ("length_mm", length_mm))
             if value is not None]
    if len(given) != 1:
        raise ConfigError(f"links: give exactly one of count, breaks, length_mm; got {given or 'none'}")
    if count is not None:
        if isinstance(count, bool) or int(count) != count or count < 1:
            raise ConfigError(f"links.count must be an integer >= 1, got {count!r}")
        out = np.linspace(0.0, 1.0, int(count) + 1)
    elif breaks is not None:
        out = _checked_breaks(breaks)
    elif length_mm is not None:  # exactly one of the three is given (checked above)
        out = _breaks_from_length(float(total_length_mm), float(length_mm))
    if np.min(np.diff(out)) < MIN_LINK_FRACTION:
        raise ConfigError(
            f"links: the shortest link spans {np.min(np.diff(out)):.3g} of the path (breaks {out.round(6).tolist()}); "
            f"expected at least {MIN_LINK_FRACTION:g}; use fewer links"
        )
    return out


def link_transforms(curve: FramedCurve, breaks: npt.ArrayLike) -> Pose:
    """S_T_E of every link of one framed curve, (n_links, 4, 4)."""
    breaks = np.asarray(breaks, float)
    poses = poses_from_frames(curve.frames(breaks), curve.points(breaks))
    return inverse_pose(poses[:-1]) @ poses[1:]


@dataclass(frozen=True)
class LinkReport:
    """One link at one q: l range, arc length mm, S_T_E (4, 4), POE split, stretch and curvature ranges."""

    index: int
    q: float
    l_start: float
    l_end: float
    length_mm: float
    transform: Pose
    poe: PoeSplit
    stats: BlendStats


@dataclass(frozen=True)
class LinkChain:
    """A blended shape split into links; forward kinematics with one q per link.

    Attributes
    ----------
    shape : the blended centerline c(q, l) with its frame mode
    breaks : (n_links + 1,) normalized l
    """

    shape: BlendedShape
    breaks: FloatArray

    @property
    def count(self) -> int:
        """Number of links."""
        return len(self.breaks) - 1

    def q_per_link(self, q: float | npt.ArrayLike) -> FloatArray:
        """One q per link (n_links,) from a scalar or a per-link sequence, checked in [0, 1]."""
        q = np.atleast_1d(np.asarray(q, float))
        if q.size == 1:
            q = np.full(self.count, float(q[0]))
        if q.shape != (self.count,) or not np.all((q >= 0.0) & (q <= 1.0)):
            raise ConfigError(
                f"q: expected one value or {self.count} values (one per link) in [0, 1], got {q.tolist()}"
            )
        return q

    def transforms(self, q: float | npt.ArrayLike) -> Pose:
        """S_T_E^(j)(q_j) of every link, (n_links, 4, 4)."""
        q = self.q_per_link(q)
        curves = self._curves(q)
        if len(curves) == 1:  # one q: every link's in one call, each pose and product its own (the same numbers)
            return link_transforms(curves[float(q[0])], self.breaks)
        out = np.empty((self.count, 4, 4))
        for j in range(self.count):
            out[j] = link_transforms(curves[float(q[j])], self.breaks[j : j + 2])[0]
        return out

    def tip2base(self, q: float | npt.ArrayLike) -> Pose:
        """Product of the link transforms: the tip frame in link 1's base frame {S}, (4, 4)."""
        out = np.eye(4)
        for transform in self.transforms(q):
            out = out @ transform
        return out

    def base2world(self, q: float | npt.ArrayLike) -> Pose:
        """F(q_1, 0): link 1's base frame in the input files' coordinates, (4, 4)."""
        q1 = float(self.q_per_link(q)[0])
        return self.shape.curve_at(q1).poses([0.0])[0]

    def tip2world(self, q: float | npt.ArrayLike) -> Pose:
        """F(q_1, 0) @ tip2base(q): the tip frame in the input files' coordinates, (4, 4)."""
        return self.base2world(q) @ self.tip2base(q)

    def reports(self, q: float | npt.ArrayLike) -> list[LinkReport]:
        """Per link: l range, length, transform, POE, stretch and curvature at its own q."""
        q = self.q_per_link(q)
        transforms = self.transforms(q)
        common = self.shape.stats_of_links(float(q[0]), self.breaks) if np.all(q == q[0]) else None
        out = []
        for j in range(self.count):
            l_range = (float(self.breaks[j]), float(self.breaks[j + 1]))
            stats = self.shape.stats_at(float(q[j]), l_range) if common is None else common[j]
            out.append(LinkReport(j, float(q[j]), *l_range, stats.length_mm, transforms[j],
                                  poe_from_pose(transforms[j]), stats))
        return out

    def _curves(self, q: FloatArray) -> dict[float, FramedSpline]:
        return {value: self.shape.curve_at(value) for value in sorted(set(q.tolist()))}


def _checked_breaks(breaks: npt.ArrayLike) -> FloatArray:
    out = np.asarray(breaks, float).ravel()
    if len(out) < 2 or not np.all(np.isfinite(out)) or out[0] != 0.0 or out[-1] != 1.0:
        raise ConfigError(f"links.breaks must start at 0 and end at 1 (normalized l), got {out.tolist()}")
    if np.any(np.diff(out) <= 0.0):
        raise ConfigError(f"links.breaks must be strictly increasing, got {out.tolist()}")
    return out


def _breaks_from_length(total: float, length: float) -> FloatArray:
    if not length > 0.0 or not total > 0.0:
        raise ConfigError(f"links.length_mm must be > 0 mm, got {length} (path length {total:.4g} mm)")
    full = int(np.floor(total / length + 1e-9))
    if full == 0:
        return np.array([0.0, 1.0])
    remainder = total - full * length
    cuts = np.arange(1, full + (1 if remainder >= REMAINDER_MERGE_FRACTION * length else 0)) * length / total
    return np.concatenate([[0.0], cuts[cuts < 1.0 - 1e-12], [1.0]])
