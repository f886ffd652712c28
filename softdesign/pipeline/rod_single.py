"""``supply: single`` in the build: the chambers sized for one design pressure P*, and the device's figures.

Each designed section (the ``design`` stage's arcs) gets one chamber on the outside of its bend, tapered along
the section (:mod:`softdesign.kinematics.rod_sizing`); P* is the lowest pressure at which every wall is the
material's ``min_wall_mm`` or more.  The figures: the chambers (angle, distance, diameter at the start, middle
and end of each section), the section's second moment, the rod model's arc at P*, its distance from the
designed chain at every export q, each chamber's winding (turns, tension per turn against the thread's limit),
the stress at P*.  The meshes and the mould carry the tapered chambers (:func:`single_layout`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.pcc_chain import feet_on_chain, section_poses
from softdesign.kinematics.rod import RodBody, section_arcs, station_poses, strains
from softdesign.kinematics.rod_sizing import (
    Limits,
    Problem,
    SingleSupply,
    design_pressure,
    largest_fitting_kappa,
    size_single,
    stations_along,
)
from softdesign.pipeline.rod_device import STATIONS_PER_SECTION, RodSetup, outlines_at, skin_radii
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
ANGLE_CONVENTION = ("angle_rad: a chamber's axis in its section's base frame, from N towards B (0 along N); the "
                    "section bends away from its chamber, towards phi = angle - pi")


@dataclass(frozen=True)
class SingleDesign:
    """The sized device and what it was sized on."""

    problem: Problem
    device: SingleSupply
    design: DesignResult


def size_case(case: Case, kinematics: KinematicsResult, fit: FitResult, design: DesignResult,
              setup: RodSetup) -> SingleDesign:
    """The single-supply device of the case at P*, or ConfigError naming the section, wall and reachable kappa."""
    if case.actuation is None:
        raise ConfigError("actuation: the case has no actuation: block")
    try:
        stations = stations_along(design.lengths, STATIONS_PER_SECTION, case.actuation.end_wall_mm)
    except ValueError as err:
        raise ConfigError(f"actuation.end_wall_mm: {err}; use a thinner end wall or longer sections") from err
    limits = Limits(setup.wall_mm + MESH_MARGIN_MM, case.actuation.feed_diameter_mm, setup.thread.diameter_mm,
                    setup.max_pressure_kpa)
    problem = Problem(stations, outlines_at(kinematics, fit, stations.s, 0.0), design.w, setup.modulus_kpa,
                      setup.backbone, limits, skin_radii(kinematics, fit, stations))
    device = design_pressure(problem)
    if device is None:
        raise ConfigError(_refusal(problem, setup))
    return SingleDesign(problem, device, design)


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


def chain_deviation_mm(body: RodBody, pressure_kpa: float, design: DesignResult, q: float) -> float:
    """Largest true distance (mm) from the rod model's centreline at ``pressure_kpa`` to the designed chain at q
    (``blend: pcc``: each section's curvature times q), the stations' ends and the tip."""
    eps0, w, _ = strains(body, [pressure_kpa])
    poses = station_poses(eps0, w, body.ds, design.base2world)
    bases, _ = section_poses(design.base2world, q * design.w, design.lengths)
    _, distance, _ = feet_on_chain(poses[:, :3, 3], bases, q * design.w, design.lengths)
    return float(np.max(distance))


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


def single_layout(layout: ChamberLayout, single: SingleDesign, station_l: FloatArray) -> ChamberLayout:
    """The meshes' and mould's layout: each section's chamber tapered as sized (its profile at the stations'
    normalized l ``station_l`` (k,), held over the end half-stations), at its middle angle; the supply line into
    section 1's chamber, coaxial (the channels joining consecutive chambers are not meshed)."""
    st, dev = single.problem.stations, single.device
    angle, distance, diameter = middle_chambers(single)
    chambers = []
    for c in layout.chambers:
        at = np.flatnonzero((st.section == c.section) & st.chamber)
        profile = tuple((float(station_l[k]), float(dev.distance_mm[k]), float(dev.diameter_mm[k])) for k in at)
        chambers.append(replace(c, angle=float(angle[c.section]), distance_mm=float(distance[c.section]),
                                diameter_mm=float(diameter[c.section]), profile=profile))
    first = chambers[0]
    feeds = tuple(replace(f, angle=first.angle, ring_mm=float(dev.feed_ring_mm[0]))
                  for f in layout.feeds if f.section == 0)
    spec = replace(layout.spec, distance_mm=float(dev.distance_mm[st.chamber].max()),
                   diameter_mm=float(dev.diameter_mm[st.chamber].min()))
    return replace(layout, spec=spec, chambers=tuple(chambers), feeds=feeds)


def chamber_lengths_mm(single: SingleDesign, pressure_kpa: float) -> FloatArray:
    """Each section's chamber axis length (n,) mm at ``pressure_kpa``: ``sum ds (1 + eps0 - w . p)``."""
    st, dev = single.problem.stations, single.device
    eps0, w, _ = strains(dev.body, [pressure_kpa])
    p = np.stack([dev.distance_mm * np.cos(dev.angle), dev.distance_mm * np.sin(dev.angle)], axis=1)
    along = st.ds * (1.0 + eps0 - np.einsum("ki,ki->k", w, p))
    n = int(st.section.max()) + 1
    return np.array([along[(st.section == i) & st.chamber].sum() for i in range(n)])


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
    deviation = {f"{q:g}": chain_deviation_mm(dev.body, q * p, design, q) for q in case.export.q_values()}
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
        "model_deviation_mm": deviation.get("1", chain_deviation_mm(dev.body, p, design, 1.0)),
        "model_deviation_by_q_mm": deviation,
        "wall_min_mm": wall,
        "stress_max_kpa": stress,
        "tension_max_n": tension,
        "tension_limit_n": setup.tension_limit_n,
        "model_reasons": reasons,
        "margins": {"wall_mm": wall - setup.wall_mm, "thread_fraction": tension / setup.tension_limit_n,
                    "stress_fraction": None if setup.tensile_kpa is None else stress / setup.tensile_kpa,
                    "model_deviation_mm": deviation.get("1", chain_deviation_mm(dev.body, p, design, 1.0))},
        "rest_lengths_mm": _rest_lengths(single) if setup.backbone == "free" else None,
    }


def _rest_lengths(single: SingleDesign) -> list[float]:
    """``backbone: free``: each section's cast length for its designed length at P* (L / (1 + mean stretch))."""
    st, dev = single.problem.stations, single.device
    eps0, _, _ = strains(dev.body, [dev.pressure_kpa])
    n = int(st.section.max()) + 1
    return [float(single.design.lengths[i] / (1.0 + np.average(eps0[st.section == i],
                                                               weights=st.ds[st.section == i])))
            for i in range(n)]


def verdict_line(summary: dict[str, Any]) -> str:
    """The build's last word on the device: one pressure bends it into the vessel, or why not."""
    if summary["model_reasons"]:
        return "device: NOT feasible: " + "; ".join(summary["model_reasons"])
    return (f"device: one pressure of {summary['design_pressure_kpa']:.1f} kPa bends it into the vessel within "
            f"{summary['model_deviation_mm']:.3g} mm (rod model), walls >= {summary['wall_min_mm']:.2f} mm, thread "
            f"at {100.0 * summary['tension_max_n'] / summary['tension_limit_n']:.1f} % of its limit")
