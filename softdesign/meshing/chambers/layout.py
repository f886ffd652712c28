"""Where a body's actuation chambers and their feed lines run: a pure layout, numbers only (no mesher).

Seed 003's section has three chambers (pneumatic muscles) 120 degrees apart
at one distance ``d`` from the backbone.  Here every link is such a section:

Chambers
    Section i's chamber j lies at angle ``beta_ij = first_angle + 120 j +
    i * 120 / n`` (n sections) in the body's rotation-minimizing frame
    (angle 0 along N, 90 along B; the RMF is continuous along the body, so the
    angle is the same measured at the section's base or anywhere in it), at
    ``distance_mm`` from the centerline, with diameter ``diameter_mm``.  It
    runs the section's length less ``end_wall_mm`` at each end (measured on
    the q = 0 body, the body as cast; in normalized l it moves with the body).
Feeds
    One per chamber, on the same ring (``ring_mm = distance_mm``) at the
    chamber's angle, parallel to the backbone from the base face (l = 0) into
    its chamber's proximal end.  Offsetting each section's chambers by
    ``120 / n`` degrees puts all 3n chambers and feeds on one ring at 3n
    distinct angles, ``120 / n`` apart: a feed never shares an angle with a
    proximal chamber or another feed, so none can cut another, and each one
    enters its chamber straight (coaxial), no jog.  An inner ring for the feeds
    was the alternative; it would need a radial jog into each chamber (not
    parallel to the backbone) and, on a 2.9 mm vessel, leaves less room than
    the gaps of the outer ring (see :func:`analytic_walls`).

Everything is in mm and radians except :class:`ActuationSpec`'s angle, which
comes from the case file in degrees.  The volume mesher conforms to these
curves: a chamber or feed at q is the centerline c(q, l) offset by
``distance (cos beta N + sin beta B)`` over its l-range, a tube of its
diameter, closed by flat discs normal to the centerline at both ends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

#: Chambers per section (seed 003's three encoders / muscles).
CHAMBERS_PER_SECTION = 3
#: How far a feed reaches into its chamber, in feed diameters (capped at a quarter of the chamber): a clean
#: boolean union, no coplanar discs.
FEED_OVERLAP_DIAMETERS = 1.0


@dataclass(frozen=True)
class ActuationSpec:
    """The case file's ``actuation`` block, validated: sizes mm, ``first_angle_deg`` degrees."""

    distance_mm: float
    diameter_mm: float
    feed_diameter_mm: float
    end_wall_mm: float
    first_angle_deg: float
    chambers_per_section: int = CHAMBERS_PER_SECTION


@dataclass(frozen=True)
class Chamber:
    """One chamber: section ``section`` (0 at the base), chamber ``index`` (0, 1, 2).

    Attributes
    ----------
    angle : rad, in the body's RMF (0 along N, pi/2 along B)
    distance_mm : mm, from the centerline to the chamber's axis
    diameter_mm : mm
    l_start, l_end : normalized l of its two flat ends (the section's, less the end walls)
    profile : a tapered chamber's (l, distance mm, diameter mm) samples, l increasing (interpolated, held at
        its ends); empty: ``distance_mm`` and ``diameter_mm`` all along (then its middle values)
    """

    section: int
    index: int
    angle: float
    distance_mm: float
    diameter_mm: float
    l_start: float
    l_end: float
    profile: tuple[tuple[float, float, float], ...] = ()

    def distance_at(self, l: npt.ArrayLike) -> FloatArray:
        """Distance of the axis from the centerline at normalized ``l`` (array), mm."""
        if not self.profile:
            return np.full(np.shape(l), self.distance_mm)
        p = np.asarray(self.profile, float)
        return np.interp(np.asarray(l, float), p[:, 0], p[:, 1])

    def diameter_at(self, l: npt.ArrayLike) -> FloatArray:
        """Diameter at normalized ``l`` (array), mm."""
        if not self.profile:
            return np.full(np.shape(l), self.diameter_mm)
        p = np.asarray(self.profile, float)
        return np.interp(np.asarray(l, float), p[:, 0], p[:, 2])


@dataclass(frozen=True)
class Feed:
    """The feed line of chamber (``section``, ``chamber``): from the base face (l = 0) to ``l_end``.

    Attributes
    ----------
    angle : rad, in the body's RMF (the chamber's angle)
    ring_mm : mm, distance of the feed's axis from the centerline
    diameter_mm : mm
    l_start : 0 (the base face; the mesher extends it through the face so it opens there)
    l_end : normalized l where it ends, inside its chamber
    """

    section: int
    chamber: int
    angle: float
    ring_mm: float
    diameter_mm: float
    l_start: float
    l_end: float


@dataclass(frozen=True)
class Channel:
    """A series channel (``supply: single``): from section ``section - 1``'s chamber into section ``section``'s.

    Its course (:mod:`softdesign.kinematics.rod_channels`) runs from inside the proximal chamber, on its axis,
    through the two end walls at the joint, turning round the body's axis the short way, into the distal chamber
    on its axis; the mesher sweeps a circle of ``diameter_mm`` in the body's normal plane along it.

    Attributes
    ----------
    section : the chamber it feeds (1 for section 1's chamber to section 2's), 0-based
    diameter_mm : mm, in the body's normal planes (across its slanted stretch it is ``diameter cos(slant)`` wide)
    course : (l, angle rad, ring mm) samples, l increasing, the angle continuous (not wrapped); linear between
        them: its first and last samples lie inside the two chambers
    """

    section: int
    diameter_mm: float
    course: tuple[tuple[float, float, float], ...]

    @property
    def l_start(self) -> float:
        """Normalized l where it starts (inside the proximal chamber)."""
        return self.course[0][0]

    @property
    def l_end(self) -> float:
        """Normalized l where it ends (inside the distal chamber)."""
        return self.course[-1][0]

    def angle_at(self, l: npt.ArrayLike) -> FloatArray:
        """Its angle (rad, from N towards B) at normalized ``l`` (array)."""
        p = np.asarray(self.course, float)
        return np.interp(np.asarray(l, float), p[:, 0], p[:, 1])

    def ring_at(self, l: npt.ArrayLike) -> FloatArray:
        """Its distance from the centerline (mm) at normalized ``l`` (array)."""
        p = np.asarray(self.course, float)
        return np.interp(np.asarray(l, float), p[:, 0], p[:, 2])


@dataclass(frozen=True)
class ChamberLayout:
    """Every chamber and feed of a body, sections proximal to distal, chambers by index; a single supply's series
    channels (``channels``: empty for Zou et al.'s three chambers, each on its own feed)."""

    spec: ActuationSpec
    breaks: tuple[float, ...]
    chambers: tuple[Chamber, ...]
    feeds: tuple[Feed, ...]
    channels: tuple[Channel, ...] = ()

    @property
    def sections(self) -> int:
        """How many sections (links)."""
        return len(self.breaks) - 1

    def section_chambers(self, section: int) -> tuple[Chamber, ...]:
        """The chambers of one section."""
        return tuple(c for c in self.chambers if c.section == section)

    def feeds_through(self, section: int) -> tuple[Feed, ...]:
        """The feeds that pass through ``section`` on their way to a more distal chamber."""
        return tuple(f for f in self.feeds if f.section > section)


def chamber_angles(spec: ActuationSpec, sections: int) -> npt.NDArray[np.float64]:
    """(n, 3) rad: ``first_angle + 120 j + i * 120 / n`` for section i, chamber j (not wrapped)."""
    step = 2.0 * np.pi / spec.chambers_per_section
    i = np.arange(sections)[:, None]
    j = np.arange(spec.chambers_per_section)[None, :]
    return np.deg2rad(spec.first_angle_deg) + step * j + i * step / sections


def plan_layout(spec: ActuationSpec, breaks: npt.ArrayLike, l_samples: npt.ArrayLike,
                s0_samples: npt.ArrayLike) -> ChamberLayout:
    """The chambers and feeds of a body whose links end at ``breaks``.

    Parameters
    ----------
    spec : ActuationSpec
    breaks : (n + 1,) float, normalized l of the links' ends, 0 first and 1 last
    l_samples : (k,) float, increasing normalized l from 0 to 1
    s0_samples : (k,) float, mm, the q = 0 centerline's arc length at ``l_samples`` (the end walls are
        measured on the body as cast)

    Returns
    -------
    ChamberLayout
        Feeds reach ``FEED_OVERLAP_DIAMETERS`` feed diameters (at most a quarter of the chamber) into
        their chamber.  Raises ValueError when a section is shorter than its two end walls.
    """
    breaks = np.asarray(breaks, float)
    l_tab, s_tab = np.asarray(l_samples, float), np.asarray(s0_samples, float)
    s_breaks = np.interp(breaks, l_tab, s_tab)
    angles = chamber_angles(spec, len(breaks) - 1)
    chambers, feeds = [], []
    for i in range(len(breaks) - 1):
        s_start, s_end = s_breaks[i] + spec.end_wall_mm, s_breaks[i + 1] - spec.end_wall_mm
        if s_end - s_start <= 0.0:
            raise ValueError(
                f"section {i + 1} is {s_breaks[i + 1] - s_breaks[i]:.3f} mm long at q = 0, shorter than its two "
                f"end walls of {spec.end_wall_mm:g} mm"
            )
        l_start, l_end = (float(v) for v in np.interp([s_start, s_end], s_tab, l_tab))
        reach = min(FEED_OVERLAP_DIAMETERS * spec.feed_diameter_mm, 0.25 * (s_end - s_start))
        l_feed = float(np.interp(s_start + reach, s_tab, l_tab))
        for j in range(spec.chambers_per_section):
            beta = float(angles[i, j])
            chambers.append(Chamber(i, j, beta, spec.distance_mm, spec.diameter_mm, l_start, l_end))
            feeds.append(Feed(i, j, beta, spec.distance_mm, spec.feed_diameter_mm, 0.0, l_feed))
    return ChamberLayout(spec, tuple(float(b) for b in breaks), tuple(chambers), tuple(feeds))


@dataclass(frozen=True)
class LayoutWalls:
    """The thinnest walls of one section's cross-section, for a round section of ``radius_mm``, mm.

    ``chamber_feed`` and ``feed_feed`` are inf where no feed passes (the last section), ``feed_skin`` too.
    """

    section: int
    radius_mm: float
    chamber_skin: float
    chamber_chamber: float
    chamber_feed: float
    feed_feed: float
    feed_skin: float

    def thinnest(self) -> tuple[str, float]:
        """The name and value of the thinnest of the five."""
        walls = {"chamber-skin": self.chamber_skin, "chamber-chamber": self.chamber_chamber,
                 "chamber-feed": self.chamber_feed, "feed-feed": self.feed_feed, "feed-skin": self.feed_skin}
        name = min(walls, key=lambda k: walls[k])
        return name, walls[name]


def analytic_walls(spec: ActuationSpec, sections: int, section: int, radius_mm: float) -> LayoutWalls:
    """Walls of ``section``'s cross-section on a straight round body of ``radius_mm`` (the layout's check).

    Chamber-skin ``R - d - D/2``; chamber-chamber ``2 d sin(60 deg) - D``; between two ring members
    ``delta`` apart in angle, ``2 d sin(delta / 2)`` less their two radii.
    """
    d, big, small = spec.distance_mm, spec.diameter_mm, spec.feed_diameter_mm
    angles = np.mod(chamber_angles(spec, sections), 2.0 * np.pi)
    own = angles[section]
    passing = angles[section + 1:].reshape(-1)

    def gap(a: npt.NDArray[np.float64], b: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        delta = np.abs(a[:, None] - b[None, :])
        delta = np.minimum(delta, 2.0 * np.pi - delta)
        return 2.0 * d * np.sin(0.5 * delta)

    inf = float("inf")
    chamber_chamber = float(np.min(gap(own, own) + np.eye(len(own)) * 1e300)) - big
    chamber_feed = float(np.min(gap(own, passing))) - 0.5 * (big + small) if passing.size else inf
    feed_feed = (float(np.min(gap(passing, passing) + np.eye(passing.size) * 1e300)) - small
                 if passing.size > 1 else inf)
    feed_skin = radius_mm - d - 0.5 * small if passing.size else inf
    return LayoutWalls(section, float(radius_mm), radius_mm - d - 0.5 * big, chamber_chamber, chamber_feed,
                       feed_feed, feed_skin)


def offset_points(centers: npt.ArrayLike, frames: npt.ArrayLike, distance_mm: float, angle: float) -> FloatArray:
    """A chamber's or feed's axis: ``c + distance (cos(angle) N + sin(angle) B)``, (n, 3) mm.

    Parameters
    ----------
    centers : (n, 3) float, mm, the centerline c(q, l)
    frames : (n, 3, 3) float, columns (N, B, T), the body's RMF there
    distance_mm : float, mm
    angle : float, rad
    """
    frames = np.asarray(frames, float)
    direction = np.cos(angle) * frames[:, :, 0] + np.sin(angle) * frames[:, :, 1]
    return np.asarray(centers, float) + distance_mm * direction
