"""The series channels of a single-supply device: where each one runs, and what the rod model sees of it (issue 41).

``supply: single`` feeds its chambers in series: the supply line runs from the
base face into section 1's chamber, and channel j joins section j's chamber to
section j + 1's through the two end walls at their joint.

Course
    In the body's parameter domain (rest arc length s from the base, mm; the
    angle from N towards B, rad; the ring, mm from the centreline), piecewise
    linear through four knots: it starts ``overlap`` inside chamber j on its
    axis (the chamber's meshed angle and its distance at its distal end), stays
    on that axis until ``turn`` past the chamber's flat end, then turns the
    short way round the axis (|angle change| <= pi) and moves to the next
    chamber's ring, linearly in s, until ``turn`` before chamber j + 1's flat
    end, and runs on that chamber's axis ``overlap`` into it.  Its section in
    each of the body's normal planes is a circle of the channel's diameter D
    (the case's ``feed_diameter_mm``, the supply line's): across its course,
    where it slants by ``atan(|d(ring e_angle)/ds|)``, it is D cos(slant) wide.
    ``overlap`` is one D (at most a quarter of the shorter chamber), ``turn`` a
    quarter D (at most a quarter of the gap between the chambers): no ring of
    the channel lies on a chamber's flat end.
Length
    Between the chambers it runs the two end walls, ``2 end_wall_mm`` along the
    body; its own length is that over cos(slant).
The rod model
    Each end-wall station the channel crosses holds it as a cavity of area
    ``pi D^2 / 4`` (the normal-plane circle) at the course's mean centre over
    the station (exact force and moment for the course; its own second moment
    about that centre is taken as the circle's, which leaves out the course's
    spread within the station: A var(c), under 1e-3 of a section's I on the
    demo).  Walls are measured on the course itself (its ends and middle in
    each station: the ring is linear there), not on the mean centre.

Pure numpy; mm and radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

#: How far a channel runs into each chamber it joins, in channel diameters (a clean boolean union, as a feed).
OVERLAP_DIAMETERS = 1.0
#: How far past a chamber's flat end the course stays on the chamber's axis, in channel diameters.
TURN_DIAMETERS = 0.25
#: Samples of a station's stretch of course for its mean centre (midpoint rule: error ~ (angle step)^2 / 12 / n^2).
MEAN_SAMPLES = 256


@dataclass(frozen=True)
class ChannelCourse:
    """Channel ``index`` (0-based) from section ``index``'s chamber into section ``index + 1``'s.

    Attributes
    ----------
    s : (4,) mm, rest arc length of the knots from the base, increasing
    angle : (4,) rad, continuous (the second and third differ by at most pi)
    ring : (4,) mm, distance of the course from the centreline
    diameter_mm : the channel's diameter in the body's normal planes
    between : mm, the two chambers' flat ends it joins (rest arc length): the course between them is the channel
        proper (before and after it runs inside a chamber)
    """

    index: int
    s: FloatArray
    angle: FloatArray
    ring: FloatArray
    diameter_mm: float
    between: tuple[float, float]

    def at(self, s: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The angle (rad) and ring (mm) at rest arc lengths ``s`` (held beyond the ends)."""
        s = np.asarray(s, float)
        return np.interp(s, self.s, self.angle), np.interp(s, self.s, self.ring)

    def centres(self, s: npt.ArrayLike) -> FloatArray:
        """(..., 2) mm, the course's centre in (N, B) at ``s``."""
        angle, ring = self.at(s)
        return np.stack([ring * np.cos(angle), ring * np.sin(angle)], axis=-1)

    def slant_max(self) -> float:
        """The course's largest slant from the body's axis, rad (the turning stretch's)."""
        length = float(self.s[2] - self.s[1])
        mean_ring = 0.5 * float(self.ring[1] + self.ring[2])
        sideways = np.hypot(mean_ring * abs(float(self.angle[2] - self.angle[1])), abs(float(self.ring[2]
                                                                                          - self.ring[1])))
        return float(np.arctan2(sideways, length))


def series_courses(chamber_ends: npt.ArrayLike, angles: npt.ArrayLike, rings: npt.ArrayLike,
                   diameter_mm: float) -> list[ChannelCourse]:
    """The courses joining consecutive chambers.

    Parameters
    ----------
    chamber_ends : (n, 2) mm, each chamber's first and last rest arc length (its flat ends)
    angles : (n,) rad, each chamber's angle (the one it is meshed at)
    rings : (n, 2) mm, each chamber's distance at its proximal and distal end
    diameter_mm : the channels' diameter
    """
    ends, a, r = np.asarray(chamber_ends, float), np.asarray(angles, float), np.asarray(rings, float)
    out = []
    for j in range(len(a) - 1):
        s0, s1 = float(ends[j, 1]), float(ends[j + 1, 0])
        shorter = min(ends[j, 1] - ends[j, 0], ends[j + 1, 1] - ends[j + 1, 0])
        overlap = min(OVERLAP_DIAMETERS * diameter_mm, 0.25 * shorter)
        turn = min(TURN_DIAMETERS * diameter_mm, 0.25 * (s1 - s0))
        change = float(np.angle(np.exp(1j * (a[j + 1] - a[j]))))  # the short way round
        out.append(ChannelCourse(j, np.array([s0 - overlap, s0 + turn, s1 - turn, s1 + overlap]),
                                 np.array([a[j], a[j], a[j] + change, a[j] + change]),
                                 np.array([r[j, 1], r[j, 1], r[j + 1, 0], r[j + 1, 0]]), float(diameter_mm),
                                 (s0, s1)))
    return out


def station_cavities(courses: list[ChannelCourse], lower: FloatArray, upper: FloatArray,
                     inside: npt.NDArray[np.bool_]) -> tuple[FloatArray, FloatArray]:
    """The channels as the rod model's cavities: mean centres (k, c, 2) mm and radii (k, c) mm.

    ``lower``, ``upper`` (k,) mm: each station's rest arc-length range; ``inside`` (k,): the station holds no
    chamber (a channel inside a chamber adds no cavity).  A channel is in a station when its course between the
    two chambers' flat ends covers the station's middle.
    """
    k, c = len(lower), len(courses)
    centres, radii = np.zeros((k, c, 2)), np.zeros((k, c))
    t = (np.arange(MEAN_SAMPLES) + 0.5) / MEAN_SAMPLES
    middle = 0.5 * (lower + upper)
    for j, course in enumerate(courses):
        crossed = np.flatnonzero(inside & (middle > course.between[0]) & (middle < course.between[1]))
        for i in crossed:
            centres[i, j] = course.centres(lower[i] + t * (upper[i] - lower[i])).mean(axis=0)
            radii[i, j] = 0.5 * course.diameter_mm
    return centres, radii


def station_rings(course: ChannelCourse, lower: float, upper: float) -> FloatArray:
    """(3,) mm: the course's ring at a station's two ends and middle (the ring is linear between knots)."""
    return course.at(np.array([lower, 0.5 * (lower + upper), upper]))[1]


def course_walls(courses: list[ChannelCourse], lower: FloatArray, upper: FloatArray, inside: npt.NDArray[np.bool_],
                 skin_mm: FloatArray, thread_diameter_mm: float) -> tuple[FloatArray, FloatArray]:
    """(k,) mm each: the thinnest channel-skin wall and channel-thread wall of each station (inf where none).

    On the course itself (:func:`station_rings`): skin ``R_skin - ring - D / 2``, thread ``ring - D / 2 - t / 2``
    (the axis thread of diameter t), as :func:`~softdesign.kinematics.rod_sizing.size_single` measures a chamber's.
    """
    skin, thread = np.full(len(lower), np.inf), np.full(len(lower), np.inf)
    middle = 0.5 * (lower + upper)
    for course in courses:
        r = 0.5 * course.diameter_mm
        for i in np.flatnonzero(inside & (middle > course.between[0]) & (middle < course.between[1])):
            rings = station_rings(course, float(lower[i]), float(upper[i]))
            skin[i] = min(skin[i], float(skin_mm[i] - rings.max() - r))
            thread[i] = min(thread[i], float(rings.min() - r - 0.5 * thread_diameter_mm))
    return skin, thread
