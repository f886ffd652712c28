"""Chambers sized by the rod model (:mod:`softdesign.kinematics.rod`): one supply pressure, or one per chamber.

``supply: single``
    One chamber per section, on the outside of the section's bend: a
    pressurised chamber bends its section away from itself, so one chamber
    placed opposite the designed bending plane phi_i reaches any (kappa_i,
    phi_i); two or three chambers per section would only add cavities (walls,
    feeds, cores) for the same two numbers.  At every station of the chamber
    its angle and diameter are solved (2 x 2 Newton on the rod model, every
    other cavity held) so that the rod model's bending at the design pressure
    P is the section's designed ``w_i = kappa_i (cos phi_i, sin phi_i)``: the
    chamber tapers with the body, ``P A(l) d(l) / (E I(l))`` constant.  It
    sits as far out as the skin wall allows (``d = R_min - wall - D / 2``,
    R_min the station's smallest outer radius): the largest arm, the smallest
    chamber.  The chambers are fed in series: one supply line, a feed on the
    first chamber's ring and angle, runs from the base face into section 1's
    chamber (it crosses that section's proximal end wall, and is in the model
    there), and each next chamber is fed from the one before by a series
    channel through the joint's two end walls (its course, diameter and
    length: :mod:`softdesign.kinematics.rod_channels`); it is a pressurised
    cavity of the end-wall stations it crosses.  No feed runs through a
    section, which is what leaves room for a chamber in a 3 mm vessel.  Every
    station is solved at once (nothing but its own chamber is pressurised
    there).  The end walls hold no chamber: the chamber's stations turn the
    section through its designed angle less what the end walls turn under
    the supply line and the channels (the section is an arc to within that).
    The design pressure P* is the lowest at which every material wall
    (chamber-skin, chamber-feed, feed-feed, feed-skin, channel-skin) is at
    least the material's and every cavity keeps its gap to the axis thread
    (:mod:`softdesign.kinematics.rod_walls`: two thread diameters, not a
    material wall); a higher pressure needs smaller chambers, but loads
    the threads more (their check follows P*).
``supply: per_chamber``
    Seed 003's three chambers per section: :mod:`softdesign.kinematics.rod_inverse`.

Pure numpy; no I/O.  Every pressure is kPa, every length mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.kinematics.rod import (
    Backbone,
    Cavities,
    RodBody,
    cavity_properties,
    outline_properties,
    rod_body,
    strains,
)
from softdesign.kinematics.rod_channels import ChannelCourse, course_walls, series_courses, station_cavities
from softdesign.kinematics.rod_walls import cavity_walls, thread_gap_mm, thread_gaps
from softdesign.types import FloatArray, IntArray

#: Newton steps of a station's chamber solve, and its convergence (relative to the target's bending).
NEWTON_STEPS = 30
NEWTON_RTOL = 1e-13
#: Solves of a single-supply design: the first, then again with the end walls' turn (the supply line's and the
#: series channels') taken off each chamber's goal, until that turn moves by at most END_WALL_ATOL_RAD (the feed's
#: and the channels' places move with the chambers; each pass cuts the change about 50-fold: a section's turn
#: was 8.7e-7 rad off after 3 passes, 1.6e-8 after 4, within 1e-9 after 5 on a three-section test body).
END_WALL_PASSES = 8
END_WALL_ATOL_RAD = 1e-11
#: Finite-difference steps of the 2 x 2 Jacobian: rad and mm.
STEP_ANGLE, STEP_DIAMETER = 1e-7, 1e-7
#: P*: from the thread's bound, the first of TRIALS log-spaced pressures that fits, then bisection in log P
#: below it to BISECT_RTOL (1e-7: P* to 0.1 Pa in 1000 kPa).
TRIALS = 25
BISECT_RTOL = 1e-7


@dataclass(frozen=True)
class Stations:
    """Stations along a body of sections, proximal first.

    Attributes
    ----------
    ds : (k,) mm rest length;  s : (k,) mm rest arc length of the middle from the base;  section : (k,) int
    chamber : (k,) bool, the section's chamber crosses the station (outside its end walls)
    """

    ds: FloatArray
    s: FloatArray
    section: IntArray
    chamber: np.ndarray


def stations_along(lengths: npt.ArrayLike, per_section: int, end_wall_mm: float) -> Stations:
    """``per_section`` equal stations in every section's chamber and one in each end wall (none when 0 mm).

    Raises ValueError for a section no longer than its two end walls.
    """
    lengths = np.asarray(lengths, float)
    ds, section, chamber = [], [], []
    for i, length in enumerate(lengths):
        inner = length - 2.0 * end_wall_mm
        if inner <= 0.0:
            raise ValueError(f"section {i + 1} is {length:.3f} mm long, not longer than its two end walls of "
                             f"{end_wall_mm:g} mm")
        walls = [end_wall_mm] if end_wall_mm > 0.0 else []
        pieces = walls + [inner / per_section] * per_section + walls
        ds += pieces
        section += [i] * len(pieces)
        chamber += [False] * len(walls) + [True] * per_section + [False] * len(walls)
    ds_array = np.asarray(ds)
    return Stations(ds_array, np.cumsum(ds_array) - 0.5 * ds_array, np.asarray(section, np.int64),
                    np.asarray(chamber))


@dataclass(frozen=True)
class Limits:
    """What a single-supply design must respect: walls and thread (mm, N, kPa)."""

    wall_mm: float
    feed_diameter_mm: float
    thread_diameter_mm: float
    max_pressure_kpa: float


@dataclass(frozen=True)
class SingleSupply:
    """A single-supply device at its design pressure.

    Attributes
    ----------
    pressure_kpa : P*
    angle, distance_mm, diameter_mm : (k,) each station's chamber (rad from N towards B; 0 mm where none)
    feed_angle, feed_ring_mm : (n,) where each chamber's inlet is (section 1's: the supply line's ring and angle)
    feed_until : (n,) mm, rest arc length where each feed ends (0: none crosses a station but the supply line)
    body : the rod (every chamber and feed on channel 0)
    walls : (k,) mm, each station's thinnest material wall;  wall_kind : (k,) its kind
    thread_gaps : (k,) mm, each station's smallest gap from a cavity to the axis thread (:mod:`rod_walls`)
    channels : the series channels, section 1's chamber to section 2's first
    """

    pressure_kpa: float
    angle: FloatArray
    distance_mm: FloatArray
    diameter_mm: FloatArray
    feed_angle: FloatArray
    feed_ring_mm: FloatArray
    feed_until: FloatArray
    body: RodBody
    walls: FloatArray
    wall_kind: tuple[str, ...]
    thread_gaps: FloatArray
    channels: tuple[ChannelCourse, ...] = ()


@dataclass(frozen=True)
class Problem:
    """A body to size: stations, outlines (k, m) mm, designed bending per section (n, 2) 1/mm, material.

    ``skin_mm`` (k,) mm: the outer radius every cavity keeps its wall from at each station (default: the
    outline's smallest; a caller may take the smallest over the station's length and over the morph).
    """

    stations: Stations
    outlines: FloatArray
    w: FloatArray
    modulus_kpa: float
    backbone: Backbone
    limits: Limits
    skin_mm: FloatArray | None = None

    def skin(self) -> FloatArray:
        """(k,) mm, the radius walls are measured from."""
        return self.outlines.min(axis=1) if self.skin_mm is None else np.asarray(self.skin_mm, float)

    def outline(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The outlines' area, first and second moments (:func:`~softdesign.kinematics.rod.outline_properties`),
        made once per problem (the sizing evaluates the model thousands of times)."""
        key = id(self.outlines)
        cached = _OUTLINES.get(key)
        if cached is None or cached[0] is not self.outlines:
            cached = (self.outlines, outline_properties(self.outlines))
            _OUTLINES.clear()
            _OUTLINES[key] = cached
        return cached[1]


#: The last problem's outline properties, keyed by the outlines array's identity (checked, not trusted).
_OUTLINES: dict[int, tuple[FloatArray, tuple[FloatArray, FloatArray, FloatArray]]] = {}


def _polar(radius: npt.ArrayLike, angle: npt.ArrayLike) -> FloatArray:
    r, a = np.asarray(radius, float), np.asarray(angle, float)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=-1)


def _bending(problem: Problem, at: IntArray, fixed: tuple[FloatArray, FloatArray], angle: FloatArray,
             diameter: FloatArray, pressure: float) -> FloatArray:
    """The rod model's ``w`` (len(at), 2) at stations ``at`` with a chamber (angle, diameter) and fixed cavities,
    every cavity at ``pressure`` (the outlines' properties are the problem's, made once)."""
    r_min = problem.skin()[at]
    distance = r_min - problem.limits.wall_mm - 0.5 * diameter
    centers = np.concatenate([fixed[0], _polar(distance, angle)[:, None, :]], axis=1)
    radii = np.concatenate([fixed[1], 0.5 * diameter[:, None]], axis=1)
    area, first, second = problem.outline()
    a, f, i = cavity_properties(centers, radii)
    body = RodBody(problem.stations.ds[at], problem.stations.section[at], area[at] - a.sum(axis=1),
                   first[at] - f.sum(axis=1), second[at] - i.sum(axis=1), a.sum(axis=1)[:, None],
                   f.sum(axis=1)[:, None, :], problem.modulus_kpa, problem.backbone, np.zeros(2))
    return strains(body, [pressure])[1]


def _solve_stations(problem: Problem, at: IntArray, fixed: tuple[FloatArray, FloatArray], target: FloatArray,
                    pressure: float, start: tuple[FloatArray, FloatArray] | None = None
                    ) -> tuple[FloatArray, FloatArray]:
    """Each station's chamber (angle rad, diameter mm) whose bending at ``pressure`` is ``target`` (len(at), 2);
    ``start``: a first guess (else a round section's estimate)."""
    scale = max(float(np.max(np.hypot(target[:, 0], target[:, 1]))), 1e-300)
    r_min = problem.skin()[at]
    i_round = np.pi * r_min**4 / 4.0
    arm = r_min - 2.0 * problem.limits.wall_mm
    moment = problem.modulus_kpa * i_round * np.hypot(target[:, 0], target[:, 1])
    diameter = np.sqrt(np.maximum(4.0 * moment / (np.pi * pressure * np.maximum(arm, 1e-3)), 1e-12))
    angle = np.arctan2(target[:, 1], target[:, 0]) + np.pi
    if start is not None:
        angle, diameter = start[0].copy(), start[1].copy()
    for _ in range(NEWTON_STEPS):
        f = _bending(problem, at, fixed, angle, diameter, pressure) - target
        if np.max(np.abs(f)) <= NEWTON_RTOL * scale:
            break
        da = (_bending(problem, at, fixed, angle + STEP_ANGLE, diameter, pressure) - target - f) / STEP_ANGLE
        dd = (_bending(problem, at, fixed, angle, diameter + STEP_DIAMETER, pressure) - target - f) / STEP_DIAMETER
        jac = np.stack([da, dd], axis=2)
        det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
        ok = np.abs(det) > 0.0
        step_a = np.where(ok, (jac[:, 1, 1] * f[:, 0] - jac[:, 0, 1] * f[:, 1]) / np.where(ok, det, 1.0), 0.0)
        step_d = np.where(ok, (-jac[:, 1, 0] * f[:, 0] + jac[:, 0, 0] * f[:, 1]) / np.where(ok, det, 1.0), 0.0)
        angle = angle - step_a
        diameter = np.clip(diameter - step_d, 0.5 * diameter, 2.0 * diameter)
    return angle, diameter


def size_single(problem: Problem, pressure: float) -> SingleSupply:
    """The chambers (and the supply line) that bend every section into its designed arc at ``pressure`` kPa.

    In series no feed crosses a chamber's station, so every station is solved at once; the supply line runs from
    the base face into section 1's chamber on its ring and angle.  The end walls hold no chamber: the chamber's
    stations turn the section through its designed angle less what the end walls turn (the supply line bends
    section 1's proximal one, the channels the others), found from the assembled rod and solved again until it
    settles (``END_WALL_ATOL_RAD``, at most ``END_WALL_PASSES`` solves).
    """
    st, n = problem.stations, int(problem.stations.section.max()) + 1
    at = np.flatnonzero(st.chamber)
    length = np.array([st.ds[st.section == i].sum() for i in range(n)])
    inner = np.array([st.ds[(st.section == i) & st.chamber].sum() for i in range(n)])
    walls_turn = np.zeros((n, 2))
    empty = (np.zeros((len(at), 0, 2)), np.zeros((len(at), 0)))
    angle, diameter = np.zeros(len(st.ds)), np.zeros(len(st.ds))
    device = None
    for _ in range(END_WALL_PASSES):
        goal = (problem.w * length[:, None] - walls_turn) / inner[:, None]
        start = (angle[at], diameter[at]) if device is not None else None
        angle[at], diameter[at] = _solve_stations(problem, at, empty, goal[st.section[at]], pressure, start)
        device = _assemble(problem, angle.copy(), diameter.copy(), pressure)
        w = strains(device.body, [pressure])[1]
        used, walls_turn = walls_turn, np.array([np.sum(st.ds[(st.section == i) & ~st.chamber, None]
                                                        * w[(st.section == i) & ~st.chamber], axis=0)
                                                 for i in range(n)])
        if np.max(np.abs(walls_turn - used)) <= END_WALL_ATOL_RAD:
            break
    assert device is not None  # END_WALL_PASSES >= 1
    return device


def _assemble(problem: Problem, angle: FloatArray, diameter: FloatArray, pressure: float) -> SingleSupply:
    """The device of the stations' chambers (angle, diameter; 0 outside the chambers) and the supply line."""
    st, n = problem.stations, int(problem.stations.section.max()) + 1
    k = len(st.ds)
    f = 0.5 * problem.limits.feed_diameter_mm
    r_min = problem.skin()
    first = np.array([np.flatnonzero((st.section == i) & st.chamber)[0] for i in range(n)])
    feed_angle = angle[first]
    feed_until = np.where(np.arange(n) == 0, st.s[first], 0.0)  # only the supply line crosses a station
    # the supply line runs on its chamber's axis, or as far in as its own skin wall needs, still inside the chamber
    centre = r_min[first] - problem.limits.wall_mm - 0.5 * diameter[first]
    crossed = st.s < feed_until[0]
    own = (r_min[crossed].min() if crossed.any() else np.inf) - problem.limits.wall_mm - f
    feed_ring = np.maximum(np.minimum(centre, own), centre - np.maximum(0.5 * diameter[first] - f, 0.0))
    distance = np.where(st.chamber, r_min - problem.limits.wall_mm - 0.5 * diameter, 0.0)
    chamber_at = st.section[:, None] == np.arange(n)[None, :]
    courses = _courses(problem, angle, distance)
    lower, upper = st.s - 0.5 * st.ds, st.s + 0.5 * st.ds
    through, through_radii = station_cavities(courses, lower, upper, ~st.chamber)
    centers = np.concatenate([np.broadcast_to(_polar(distance, angle)[:, None, :], (k, n, 2)),
                              np.broadcast_to(_polar(feed_ring, feed_angle)[None], (k, n, 2))], axis=1)
    radii = np.concatenate([np.where(chamber_at & st.chamber[:, None], 0.5 * diameter[:, None], 0.0),
                            np.where(st.s[:, None] < feed_until[None, :], f, 0.0)], axis=1)
    cavities = Cavities(np.concatenate([centers, through], axis=1), np.concatenate([radii, through_radii], axis=1),
                        np.zeros(2 * n + len(courses), np.int64))
    body = rod_body(st.ds, st.section, problem.outlines, cavities, problem.modulus_kpa, problem.backbone)
    t = problem.limits.thread_diameter_mm
    skin, thread = course_walls(courses, lower, upper, ~st.chamber, r_min, t)
    walls, kinds = cavity_walls(r_min, centers, radii, ["chamber"] * n + ["feed"] * n, (("channel-skin", skin),))
    return SingleSupply(pressure, angle, distance, diameter, feed_angle, feed_ring, feed_until, body, walls,
                        tuple(kinds), thread_gaps(centers, radii, t, thread), tuple(courses))


def middle_angles(stations: Stations, angle: FloatArray) -> FloatArray:
    """(n,) rad: each section's chamber angle at its middle rest arc length (the angle it is meshed at)."""
    out = []
    for i in range(int(stations.section.max()) + 1):
        at = np.flatnonzero((stations.section == i) & stations.chamber)
        s = stations.s[at]
        out.append(float(np.interp(0.5 * (s[0] + s[-1]), s, np.unwrap(angle[at]))))
    return np.asarray(out)


def _courses(problem: Problem, angle: FloatArray, distance: FloatArray) -> list[ChannelCourse]:
    """The series channels between the chambers as meshed (middle angle, end distances), the case's feed size."""
    st, n = problem.stations, int(problem.stations.section.max()) + 1
    ends, rings = np.zeros((n, 2)), np.zeros((n, 2))
    for i in range(n):
        at = np.flatnonzero((st.section == i) & st.chamber)
        ends[i] = st.s[at[0]] - 0.5 * st.ds[at[0]], st.s[at[-1]] + 0.5 * st.ds[at[-1]]
        rings[i] = distance[at[0]], distance[at[-1]]
    return series_courses(ends, middle_angles(st, angle), rings, problem.limits.feed_diameter_mm)


def fits(device: SingleSupply, limits: Limits) -> bool:
    """Whether every material wall is at least ``limits.wall_mm`` and every gap to the axis thread at least
    :func:`~softdesign.kinematics.rod_walls.thread_gap_mm` (to 1e-12 relative)."""
    gap = thread_gap_mm(limits.thread_diameter_mm)
    return bool(np.all(device.walls >= limits.wall_mm * (1.0 - 1e-12))
                and np.all(device.thread_gaps >= gap * (1.0 - 1e-12)))


def _biggest(problem: Problem, at: IntArray) -> FloatArray:
    """The widest chamber (mm) at stations ``at`` that keeps the skin wall and the gap to the axis thread:
    ``D = R_skin - wall - gap - t / 2`` (the chamber at ``R_skin - wall - D / 2``)."""
    lim = problem.limits
    return np.asarray(problem.skin()[at] - lim.wall_mm - thread_gap_mm(lim.thread_diameter_mm)
                      - 0.5 * lim.thread_diameter_mm, float)


def thread_bound_kpa(problem: Problem) -> float:
    """The pressure below which some station's chamber would reach past its wall to the axis thread, kPa.

    At a fixed chamber the bending is linear in the pressure: with the largest chamber the skin and thread walls
    allow (:func:`_biggest`), placed opposite its target, a station needs ``|target| / |w(1 kPa)|``.
    """
    st = problem.stations
    at = np.flatnonzero(st.chamber)
    n = int(st.section.max()) + 1
    spread = np.array([st.ds[st.section == i].sum() / st.ds[(st.section == i) & st.chamber].sum() for i in range(n)])
    target = (spread[:, None] * problem.w)[st.section[at]]
    biggest = _biggest(problem, at)
    if np.any(biggest <= 0.0):
        return float("inf")
    angle = np.arctan2(target[:, 1], target[:, 0]) + np.pi
    empty = (np.zeros((len(at), 0, 2)), np.zeros((len(at), 0)))
    unit = np.hypot(*_bending(problem, at, empty, angle, biggest, 1.0).T)
    return float(np.max(np.hypot(target[:, 0], target[:, 1]) / unit))


def design_pressure(problem: Problem) -> SingleSupply | None:
    """The device at P*, the lowest pressure (to ``BISECT_RTOL``) whose walls all fit; None when none of the trial
    pressures up to the limits' ``max_pressure_kpa`` does.

    The search starts at :func:`thread_bound_kpa` (no lower pressure fits), then tries ``TRIALS`` log-spaced
    pressures up to the limit (the fit is not monotone: at high pressures a chamber shrinks below its supply line)
    and bisects below the first that fits.
    """
    top = problem.limits.max_pressure_kpa
    start = thread_bound_kpa(problem)
    if not start <= top:
        return None
    low = start * (1.0 - 1e-3)  # the bound's chamber angle is the target's: within this of the solved one
    high: SingleSupply | None = None
    for p in np.concatenate([[start], np.geomspace(start, top, TRIALS)[1:]]):
        device = size_single(problem, float(p))
        if fits(device, problem.limits):
            high = device
            break
        low = float(p)
    if high is None:
        return None
    while high.pressure_kpa - low > BISECT_RTOL * high.pressure_kpa:
        middle = float(np.sqrt(low * high.pressure_kpa))
        device = size_single(problem, middle)
        if fits(device, problem.limits):
            high = device
        else:
            low = middle
    return high


def largest_fitting_kappa(problem: Problem, section: int, pressure: float) -> float:
    """The largest curvature (1/mm) section ``section``'s stations all reach at ``pressure`` with the biggest
    chamber its walls allow (skin and axis thread; feeds ignored), bending as designed."""
    st = problem.stations
    at = np.flatnonzero((st.section == section) & st.chamber)
    biggest = np.maximum(_biggest(problem, at), 0.0)
    target = problem.w[section]
    angle = np.full(len(at), float(np.arctan2(target[1], target[0]) + np.pi))
    empty = (np.zeros((len(at), 0, 2)), np.zeros((len(at), 0)))
    w = _bending(problem, at, empty, angle, biggest, pressure)
    return float(np.min(np.hypot(w[:, 0], w[:, 1])))
