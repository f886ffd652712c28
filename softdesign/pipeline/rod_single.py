"""``supply: single`` in the build: the chambers sized for one design pressure P*, and the device's figures.

Each designed section (the ``design`` stage's arcs) gets one chamber on the outside of its bend, tapered along
the section (:mod:`softdesign.kinematics.rod_sizing`); P* is the lowest pressure at which every wall is the
material's ``min_wall_mm`` or more.  The figures: the chambers (angle, distance, diameter at the start, middle
and end of each section), the section's second moment, the rod model's arc at P*, its distance from the
designed chain at every export q, each chamber's winding (turns, tension per turn against the thread's limit),
the stress at P*.  The meshes and the mould carry the tapered chambers (:func:`single_layout`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import RodBody, section_arcs, station_poses, strains
from softdesign.kinematics.rod_sizing import (
    Limits,
    Problem,
    SingleSupply,
    Stations,
    design_pressure,
    largest_fitting_kappa,
    size_single,
    stations_along,
)
from softdesign.kinematics.rod_walls import THREAD_GAP_DIAMETERS, thread_gap_mm
from softdesign.meshing.chambers.layout import Channel, Feed
from softdesign.pipeline.rod_device import (
    STATIONS_PER_SECTION,
    RodSetup,
    outlines_at,
    outlines_at_l,
    skin_radii,
    skin_radii_l,
    station_l,
)
from softdesign.pipeline.rod_evaluate import chain_deviation, chamber_axis_lengths
from softdesign.pipeline.rod_free import REST_SIZINGS, l_from_s, morph_document, settled
from softdesign.types import FloatArray

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.meshing.chambers.layout import ChamberLayout
    from softdesign.pipeline.stages.design import DesignResult
    from softdesign.pipeline.stages.fit import FitResult
    from softdesign.pipeline.stages.kinematics import KinematicsResult

#: Sized walls are this much over the material's: the meshes' polygons (equal-area chambers, a faceted skin) reach
#: up to about 0.005 mm further than the circles the rod model sizes, and the build measures walls on the meshes.
MESH_MARGIN_MM = 0.01
#: Samples of a series channel's course over its turning stretch in the layout (the mesher's rings are these and
#: the body's rings between them): 2 degrees of a 180-degree turn apart at most.
COURSE_SAMPLES = 91
THREAD_GAP_RULE = (f"a chamber's or channel's surface keeps {THREAD_GAP_DIAMETERS:g} thread diameters from the axis "
                   "thread's surface (its own hoop winding, then silicone): the thread is not a cavity, so "
                   "min_wall_mm does not apply (softdesign/kinematics/rod_walls.py)")
ANGLE_CONVENTION = ("angle_rad: a chamber's axis in its section's base frame, from N towards B (0 along N); the "
                    "section bends away from its chamber, towards phi = angle - pi")


@dataclass(frozen=True)
class SingleDesign:
    """The sized device and what it was sized on; ``rest_lengths`` (n,) mm with ``backbone: free`` (the cast
    sections, :mod:`softdesign.pipeline.rod_free`), None when the axis thread keeps the designed lengths."""

    problem: Problem
    device: SingleSupply
    design: DesignResult
    rest_lengths: FloatArray | None = None

    def l_of(self, kinematics: KinematicsResult) -> Callable[[FloatArray], FloatArray]:
        """Rest arc length (mm) -> the body's normalized l."""
        if self.rest_lengths is None:
            return lambda s: station_l(kinematics, s)
        rest, breaks = self.rest_lengths, self.design.breaks
        return lambda s: l_from_s(breaks, rest, s)


def size_case(case: Case, kinematics: KinematicsResult, fit: FitResult, design: DesignResult,
              setup: RodSetup) -> SingleDesign:
    """The single-supply device of the case at P*, or ConfigError naming the section, wall and reachable kappa.

    ``backbone: free``: sized on the rest lengths, solved in turn with them until they settle (:mod:`rod_free`)."""
    if case.actuation is None:
        raise ConfigError("actuation: the case has no actuation: block")
    limits = Limits(setup.wall_mm + MESH_MARGIN_MM, case.actuation.feed_diameter_mm, setup.thread.diameter_mm,
                    setup.max_pressure_kpa)
    if setup.backbone != "free":
        stations = _stations(case, design.lengths)
        problem = Problem(stations, outlines_at(kinematics, fit, stations.s, 0.0), design.w, setup.modulus_kpa,
                          setup.backbone, limits, skin_radii(kinematics, fit, stations))
        return SingleDesign(problem, _sized(problem, setup), design)
    rest = np.asarray(design.lengths, float)
    for _ in range(REST_SIZINGS):
        stations = _stations(case, rest)
        l_of = functools.partial(l_from_s, design.breaks, rest)
        turn = design.w * (design.lengths / rest)[:, None]  # the designed turn over the rest length
        problem = Problem(stations, outlines_at_l(fit, l_of(stations.s), 0.0), turn, setup.modulus_kpa,
                          setup.backbone, limits, skin_radii_l(fit, stations, l_of))
        device = _sized(problem, setup)
        eps0 = strains(device.body, [device.pressure_kpa])[0]
        mean = np.array([np.average(eps0[stations.section == i], weights=stations.ds[stations.section == i])
                         for i in range(len(rest))])
        rest, before = np.asarray(design.lengths, float) / (1.0 + mean), rest
        if settled(before, rest):
            break
    return SingleDesign(problem, device, design, before)


def _stations(case: Case, lengths: FloatArray) -> Stations:
    assert case.actuation is not None
    try:
        return stations_along(lengths, STATIONS_PER_SECTION, case.actuation.end_wall_mm)
    except ValueError as err:
        raise ConfigError(f"actuation.end_wall_mm: {err}; use a thinner end wall or longer sections") from err


def _sized(problem: Problem, setup: RodSetup) -> SingleSupply:
    device = design_pressure(problem)
    if device is None:
        raise ConfigError(_refusal(problem, setup))
    return device


def _refusal(problem: Problem, setup: RodSetup) -> str:
    """Why no pressure fits: the section with the thinnest wall at the highest pressure tried, and its reach."""
    top = setup.max_pressure_kpa
    device = size_single(problem, top)
    worst = int(np.argmin(device.walls))
    section = int(problem.stations.section[worst])
    reach = largest_fitting_kappa(problem, section, top)
    need = float(np.hypot(*problem.w[section]))
    return (f"actuation (supply: single): no pressure up to {top:.0f} kPa ({setup.material}'s tensile strength) "
            f"leaves every wall >= min_wall_mm {setup.wall_mm:g} ({setup.material}): at {top:.0f} kPa section "
            f"{section + 1}'s {device.wall_kind[worst]} wall is {device.walls[worst]:.3f} mm; with the largest "
            f"chamber its walls allow it reaches kappa {reach:.4f} 1/mm, it needs {need:.4f}; use a material with a "
            "thinner wall (material.min_wall_mm) or a stiffer thread, or gentler sections (a larger "
            "design.tolerance_mm, more links)")


def middle_chambers(single: SingleDesign) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Per section the chamber's angle (rad), distance and diameter (mm) at the chamber's middle arc length."""
    st, dev = single.problem.stations, single.device
    n = int(st.section.max()) + 1
    out = np.zeros((3, n))
    for i in range(n):
        at = np.flatnonzero((st.section == i) & st.chamber)
        for row, values in enumerate((np.unwrap(dev.angle[at]), dev.distance_mm[at], dev.diameter_mm[at])):
            out[row, i] = _at_ends(values, st.s[at])["middle"]
    return out[0], out[1], out[2]


def chain_deviation_mm(body: RodBody, pressure_kpa: float, design: DesignResult, q: float,
                       rest: FloatArray | None = None) -> float:
    """Largest true distance (mm) from the rod model's centreline at ``pressure_kpa`` to the designed chain at q
    (:func:`~softdesign.pipeline.rod_evaluate.chain_deviation`; ``rest``: the free backbone's rest lengths)."""
    return chain_deviation(body, pressure_kpa, design.base2world, design.w, design.lengths, q, rest)


def _at_ends(values: FloatArray, s: FloatArray) -> dict[str, float]:
    """``{start, middle, end}`` of a quantity over a chamber's stations (middle: at the middle arc length)."""
    middle = float(np.interp(0.5 * (s[0] + s[-1]), s, values))
    return {"start": float(values[0]), "middle": middle, "end": float(values[-1])}


def section_figures(single: SingleDesign, setup: RodSetup) -> list[dict[str, Any]]:
    """Per section, base first: its chamber, second moment at the middle, the model's arc at P*, the winding."""
    st, dev = single.problem.stations, single.device
    eps0, w, _ = strains(dev.body, [dev.pressure_kpa])
    poses = station_poses(eps0, w, dev.body.ds, np.eye(4))
    kappa, phi, length = section_arcs(dev.body, poses, eps0)
    out = []
    for i in range(len(kappa)):
        at = np.flatnonzero((st.section == i) & st.chamber)
        s = st.s[at]
        bend = single.design.w[i] / max(float(np.hypot(*single.design.w[i])), 1e-300)
        bend = bend if np.any(bend) else np.array([1.0, 0.0])
        second = np.einsum("i,kij,j->k", bend, dev.body.second[at], bend)
        chamber_length = float(np.sum(st.ds[at]))
        radius = 0.5 * float(dev.diameter_mm[at].max())
        tension = dev.pressure_kpa * radius * setup.pitch_mm * 1e-3
        out.append({
            "section": i + 1,
            "chambers": [{"angle_rad": _at_ends(np.unwrap(dev.angle[at]), s),
                          "distance_mm": _at_ends(dev.distance_mm[at], s),
                          "diameter_mm": _at_ends(dev.diameter_mm[at], s),
                          "diameter_max_mm": 2.0 * radius,
                          "length_mm": chamber_length,
                          "turns": int(np.ceil(chamber_length / setup.pitch_mm)),
                          "tension_per_turn_n": tension,
                          "tension_limit_n": setup.tension_limit_n}],
            "second_moment_mm4": float(np.interp(0.5 * (s[0] + s[-1]), s, second)),
            "model": {"kappa": float(kappa[i]), "phi": float(phi[i]), "length": float(length[i])},
            "designed": {"kappa": float(np.hypot(*single.design.w[i])),
                         "phi": float(np.arctan2(single.design.w[i][1], single.design.w[i][0])),
                         "length": float(single.design.lengths[i])},
            "wall_min_mm": float(dev.walls[st.section == i].min()),
            "wall_kind": dev.wall_kind[int(np.flatnonzero(st.section == i)[np.argmin(dev.walls[st.section == i])])],
        })
    return out


def stress_kpa(body: RodBody, pressure_kpa: float, outlines: FloatArray) -> float:
    """The largest stress at P* (kPa): the axial E |eps| on the outline, or the pressure on a cavity's wall."""
    eps0, w, _ = strains(body, [pressure_kpa])
    m = outlines.shape[1]
    a = 2.0 * np.pi * np.arange(m) / m
    y = outlines[..., None] * np.stack([np.cos(a), np.sin(a)], axis=1)[None]
    eps = eps0[:, None] - np.einsum("kmi,ki->km", y, w)
    return float(max(body.modulus_kpa * np.max(np.abs(eps)), pressure_kpa))


def single_layout(layout: ChamberLayout, single: SingleDesign, l_of: Callable[[FloatArray], FloatArray]
                  ) -> ChamberLayout:
    """The meshes' and mould's layout: each section's chamber tapered as sized (its profile at the stations'
    normalized l, ``l_of`` rest arc lengths (k,) mm, held over the end half-stations), at its middle angle; the
    supply line into section 1's chamber, coaxial; the series channels on their courses (``COURSE_SAMPLES``
    samples over each one's turning stretch: linear in s as the rod model's)."""
    st, dev = single.problem.stations, single.device
    angle, distance, diameter = middle_chambers(single)
    station_l = l_of(st.s)
    chambers = []
    for c in layout.chambers:
        at = np.flatnonzero((st.section == c.section) & st.chamber)
        profile = tuple((float(station_l[k]), float(dev.distance_mm[k]), float(dev.diameter_mm[k])) for k in at)
        chambers.append(replace(c, angle=float(angle[c.section]), distance_mm=float(distance[c.section]),
                                diameter_mm=float(diameter[c.section]), profile=profile))
        if single.rest_lengths is not None:  # the planned ends are on the designed lengths: the rest body's here
            edges = l_of(np.array([st.s[at[0]] - 0.5 * st.ds[at[0]], st.s[at[-1]] + 0.5 * st.ds[at[-1]]]))
            chambers[-1] = replace(chambers[-1], l_start=float(edges[0]), l_end=float(edges[1]))
    first = chambers[0]
    feeds = tuple(replace(f, angle=first.angle, ring_mm=float(dev.feed_ring_mm[0]))
                  for f in layout.feeds if f.section == 0)
    if single.rest_lengths is not None:  # the supply line ends inside chamber 1 as planned (its reach in mm)
        feeds = tuple(replace(f, l_end=float(l_of(np.array([_reach_s(layout, f, st)]))[0])) for f in feeds)
    spec = replace(layout.spec, distance_mm=float(dev.distance_mm[st.chamber].max()),
                   diameter_mm=float(dev.diameter_mm[st.chamber].min()))
    channels = []
    for course in dev.channels:
        s = np.concatenate([course.s[:2], np.linspace(course.s[1], course.s[2], COURSE_SAMPLES)[1:-1], course.s[2:]])
        a, ring = course.at(s)
        channels.append(Channel(course.index + 1, course.diameter_mm,
                                tuple(zip(l_of(s).tolist(), a.tolist(), ring.tolist(), strict=True))))
    return replace(layout, spec=spec, chambers=tuple(chambers), feeds=feeds, channels=tuple(channels))


def _reach_s(layout: ChamberLayout, feed: Feed, st: Stations) -> float:
    """Rest arc length (mm) where the supply line ends: as far into chamber 1 as planned (the planned reach in l
    over the planned chamber's length in l, times the rest chamber's length in mm)."""
    planned = layout.chambers[0]
    at = np.flatnonzero((st.section == 0) & st.chamber)
    start, end = st.s[at[0]] - 0.5 * st.ds[at[0]], st.s[at[-1]] + 0.5 * st.ds[at[-1]]
    fraction = (feed.l_end - planned.l_start) / (planned.l_end - planned.l_start)
    return float(start + fraction * (end - start))


def chamber_lengths_mm(single: SingleDesign, pressure_kpa: float) -> FloatArray:
    """Each section's chamber axis length (n,) mm at ``pressure_kpa``
    (:func:`~softdesign.pipeline.rod_evaluate.chamber_axis_lengths`)."""
    dev = single.device
    return chamber_axis_lengths(dev.body, pressure_kpa, dev.distance_mm, dev.angle, single.problem.stations.chamber)


def rod_extra(single: SingleDesign) -> dict[str, Any]:
    """The rod file's ``single`` part (:mod:`softdesign.pipeline.rod_file`)."""
    dev, design = single.device, single.design
    return {"supply": "single", "single": {
        "design_pressure_kpa": dev.pressure_kpa, "distance_mm": dev.distance_mm.tolist(), "angle": dev.angle.tolist(),
        "base2world": np.asarray(design.base2world, float).tolist(), "w": np.asarray(design.w, float).tolist(),
        "lengths": np.asarray(design.lengths, float).tolist(),
        "rest_lengths": None if single.rest_lengths is None else single.rest_lengths.tolist()}}


def single_rows(single: SingleDesign, grid: list[tuple[float, bool]], arcs: dict[float, list[Any]]
                ) -> list[dict[str, Any]]:
    """actuation.csv's rows: at every q one row per section (its one chamber) at ``q P*``.

    ``arcs``: each q's best arcs of the body's links (:func:`~softdesign.kinematics.pcc_fit.fit_links`).
    """
    dev = single.device
    angle, distance, _ = middle_chambers(single)
    rest = chamber_lengths_mm(single, 0.0)
    rows = []
    for q, export in grid:
        lengths = chamber_lengths_mm(single, q * dev.pressure_kpa)
        for i, f in enumerate(arcs[q]):
            rows.append({"q": q, "export": int(export), "section": i + 1, "chamber": 1,
                         "angle_deg": float(np.rad2deg(angle[i])), "distance_mm": float(distance[i]),
                         "length_mm": float(lengths[i]), "extension": float(lengths[i] / rest[i]),
                         "arc_kappa": f.kappa, "arc_phi": f.phi, "arc_length_mm": f.length,
                         "arc_misfit_mm": f.backbone_max_mm, "pressure_kpa": q * dev.pressure_kpa})
    return rows


def single_summary(case: Case, single: SingleDesign, setup: RodSetup) -> dict[str, Any]:
    """The summary's rod-model figures and the verdict's reasons and margins for ``supply: single``."""
    dev, design = single.device, single.design
    p = dev.pressure_kpa
    sections = section_figures(single, setup)
    rest = single.rest_lengths
    deviation = {f"{q:g}": chain_deviation_mm(dev.body, q * p, design, q, rest) for q in case.export.q_values()}
    tension = max(c["tension_per_turn_n"] for s in sections for c in s["chambers"])
    stress = stress_kpa(dev.body, p, single.problem.outlines)
    wall = float(dev.walls.min())
    reasons = []
    if tension > setup.tension_limit_n:
        pitch = setup.pitch_mm * setup.tension_limit_n / tension
        reasons.append(f"hoop tension {tension:.3g} N per turn > the thread's limit {setup.tension_limit_n:.3g} N "
                       f"({setup.thread.name}, breaking load / safety factor {setup.safety_factor:g}); use "
                       f"actuation.reinforcement.pitch_mm <= {pitch:.3g} or a stronger thread")
    if setup.tensile_kpa is not None and stress > setup.tensile_kpa:
        reasons.append(f"stress {stress:.4g} kPa at P* > {setup.material}'s tensile strength "
                       f"{setup.tensile_kpa:.4g} kPa; use a stronger material (material.name)")
    return {
        "supply": "single",
        "backbone": setup.backbone,
        "design_pressure_kpa": p,
        "body_modulus_kpa": setup.modulus_kpa,
        "reinforcement": setup.reinforcement(),
        "angle_convention": ANGLE_CONVENTION,
        "sections": sections,
        "model_deviation_mm": deviation.get("1", chain_deviation_mm(dev.body, p, design, 1.0, rest)),
        "model_deviation_by_q_mm": deviation,
        "wall_min_mm": wall,
        "thread_gap_min_mm": float(dev.thread_gaps.min()),
        "thread_gap_rule_mm": thread_gap_mm(single.problem.limits.thread_diameter_mm),
        "thread_gap_rule": THREAD_GAP_RULE,
        "stress_max_kpa": stress,
        "tension_max_n": tension,
        "tension_limit_n": setup.tension_limit_n,
        "model_reasons": reasons,
        "margins": {"wall_mm": wall - setup.wall_mm, "thread_fraction": tension / setup.tension_limit_n,
                    "stress_fraction": None if setup.tensile_kpa is None else stress / setup.tensile_kpa,
                    "model_deviation_mm": deviation.get("1", chain_deviation_mm(dev.body, p, design, 1.0, rest))},
        "rest_lengths_mm": None if rest is None else rest.tolist(),
        "free_morph": None if rest is None else morph_document(design.base2world, design.w, design.lengths, rest,
                                                               design.breaks),
    }


def verdict_line(summary: dict[str, Any]) -> str:
    """The build's last word on the device: one pressure bends it into the vessel, or why not."""
    if summary["model_reasons"]:
        return "device: NOT feasible: " + "; ".join(summary["model_reasons"])
    return (f"device: one pressure of {summary['design_pressure_kpa']:.1f} kPa bends it into the vessel within "
            f"{summary['model_deviation_mm']:.3g} mm (rod model), walls >= {summary['wall_min_mm']:.2f} mm, thread "
            f"at {100.0 * summary['tension_max_n'] / summary['tension_limit_n']:.1f} % of its limit")
