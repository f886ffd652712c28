"""The rod model on a case's body: its stations and outlines, the material's modulus, the thread (issue 41).

The core is :mod:`softdesign.kinematics.rod` and :mod:`softdesign.kinematics.rod_sizing`; this module gives it
the case's numbers: the cast body (q = 0) cut into stations along each section, the fitted radius profile at
each station (``OUTLINE_ANGLES`` angles, the body as cast), E = 3 mu from the material's law, the wall from
``material.min_wall_mm``, the thread from softdesign/data/threads.yaml.  The single-supply device's figures are
in :mod:`softdesign.pipeline.rod_single`, the per-chamber pressures in :func:`per_chamber_rows`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import Backbone, Cavities, RodBody, rod_body
from softdesign.kinematics.rod_inverse import per_chamber_pressures
from softdesign.kinematics.rod_sizing import Stations
from softdesign.materials.threads import Thread, thread_presets
from softdesign.types import FloatArray

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.meshing.chambers.layout import ChamberLayout
    from softdesign.pipeline.stages.fit import FitResult
    from softdesign.pipeline.stages.kinematics import KinematicsResult

#: Angles of a station's outline (the fitted radius profile), 5 degrees apart.
OUTLINE_ANGLES = 72
#: Stations in each section's chamber (plus one per end wall): the taper is smooth over a section.
STATIONS_PER_SECTION = 16
#: The highest design pressure tried when the material gives no tensile strength, kPa.
MAX_PRESSURE_KPA = 1000.0
#: Why a body without reinforcement gets no pressure from the rod model.
NO_REINFORCEMENT = (
    "actuation.reinforcement.kind: none: a bare chamber balloons, and in an incompressible body the pressure on "
    "its side wall cancels the moment of its end caps, kappa = (1 - 2 nu) P A d / (E I) = 0 at nu = 1/2, so the "
    "rod model predicts no bend; use reinforcement: {kind: hoop} (a thread wound round each chamber), or "
    "`softdesign simulate CASE` for the finite elements' answer")


@dataclass(frozen=True)
class RodSetup:
    """The case's numbers for the rod model: E (kPa), the material's wall (mm) and strength (kPa), the thread."""

    modulus_kpa: float
    wall_mm: float
    tensile_kpa: float | None
    material: str
    thread: Thread
    pitch_mm: float
    safety_factor: float
    backbone: Backbone

    @property
    def tension_limit_n(self) -> float:
        """The most a turn may carry: the thread's breaking load over the safety factor, N."""
        return self.thread.breaking_load_n / self.safety_factor

    @property
    def max_pressure_kpa(self) -> float:
        """The highest pressure tried: the tensile strength (a cavity's wall carries -P), else MAX_PRESSURE_KPA."""
        return self.tensile_kpa if self.tensile_kpa is not None else MAX_PRESSURE_KPA

    def reinforcement(self) -> dict[str, Any]:
        """The summary's ``reinforcement`` entry."""
        return {"kind": "hoop", "pitch_mm": self.pitch_mm, "thread": self.thread.as_dict(),
                "safety_factor": self.safety_factor}


def _material(case: Case) -> tuple[float | None, float | None, str]:
    """The case material's initial shear modulus mu (kPa, 2 C1 of its law), tensile strength (kPa) and name."""
    from softdesign.materials.data import material_presets

    m = case.material
    if m is None:
        return None, None, "none"
    if m.custom is not None:
        return 2.0 * m.custom.law.c1_kpa, 1000.0 * m.custom.tensile_strength_mpa, m.limits().name
    if m.name is None:
        return None, None, m.limits().name
    preset = material_presets()[m.name]
    mu = None if preset.law_params is None else 2.0 * preset.law_params[1]
    return mu, preset.tensile_strength_kpa, m.limits().name


def rod_setup(case: Case) -> RodSetup | str:
    """The rod model's numbers, or why there are none (no reinforcement; no material law or wall)."""
    actuation = case.actuation
    if actuation is None:
        return "no actuation: block"
    if actuation.reinforcement.kind == "none":
        return NO_REINFORCEMENT
    mu, tensile, name = _material(case)
    limits = case.material.limits() if case.material is not None else None
    if mu is None or limits is None or limits.min_wall_mm is None:
        return ("the rod model takes E = 3 mu from the material's law and the wall from its min_wall_mm: give "
                "material: {name: <preset>} (softdesign materials lists them) or material.custom")
    r = actuation.reinforcement
    return RodSetup(3.0 * mu, float(limits.min_wall_mm), tensile, name, thread_presets()[r.thread.name],
                    r.pitch_mm, r.safety_factor, actuation.backbone)


def station_l(kinematics: KinematicsResult, s: FloatArray) -> FloatArray:
    """Normalized l (k,) of rest arc lengths ``s`` (k,) mm from the base on the cast (q = 0) body."""
    curve0 = kinematics.chain.shape.curve_at(0.0).curve
    l_table = curve0.dense_l()
    return np.clip(np.interp(s, curve0.arc_length(l_table), l_table), 0.0, 1.0)


def outlines_at(kinematics: KinematicsResult, fit: FitResult, s: FloatArray, q: float = 0.0) -> FloatArray:
    """The body's radii (k, OUTLINE_ANGLES) mm at q (0: as cast) at rest arc lengths ``s`` (k,) mm from the base."""
    return outlines_at_l(fit, station_l(kinematics, s), q)


def outlines_at_l(fit: FitResult, l: FloatArray, q: float = 0.0) -> FloatArray:
    """The body's radii (k, OUTLINE_ANGLES) mm at q at normalized ``l`` (k,)."""
    a = 2.0 * np.pi * np.arange(OUTLINE_ANGLES) / OUTLINE_ANGLES
    return np.asarray(fit.field.evaluate_grid(q, np.clip(l, 0.0, 1.0), a), float)


def skin_radii(kinematics: KinematicsResult, fit: FitResult, stations: Stations) -> FloatArray:
    """(k,) mm: each station's smallest radius over its length (both ends and middle), every angle, at q = 0 and
    1: the skin the build measures walls against at every q (the radius profile morphs with q)."""
    return skin_radii_l(fit, stations, lambda s: station_l(kinematics, s))


def skin_radii_l(fit: FitResult, stations: Stations, l_of: Callable[[FloatArray], FloatArray]) -> FloatArray:
    """:func:`skin_radii` with the stations' rest arc lengths mapped to l by ``l_of``."""
    l = l_of(np.concatenate([stations.s - 0.5 * stations.ds, stations.s, stations.s + 0.5 * stations.ds]))
    radii = np.minimum(outlines_at_l(fit, l, 0.0), outlines_at_l(fit, l, 1.0)).min(axis=1)
    return np.asarray(radii.reshape(3, -1).min(axis=0), float)


def section_rest_lengths(kinematics: KinematicsResult) -> FloatArray:
    """Each link's length on the cast body (q = 0), mm."""
    curve0 = kinematics.chain.shape.curve_at(0.0).curve
    return np.diff(np.asarray(curve0.arc_length(np.asarray(kinematics.chain.breaks, float)), float))


def layout_stations(layout: ChamberLayout, lengths: FloatArray) -> Stations:
    """Stations of a per-chamber layout: ``STATIONS_PER_SECTION`` in each chamber, one per end wall."""
    from softdesign.kinematics.rod_sizing import stations_along

    return stations_along(lengths, STATIONS_PER_SECTION, layout.spec.end_wall_mm)


def layout_body(layout: ChamberLayout, stations: Stations, outlines: FloatArray, setup: RodSetup) -> RodBody:
    """The rod of seed 003's layout: chamber j of section i and its feed on channel 3 i + j."""
    k, count = len(stations.ds), len(layout.chambers)
    starts = np.concatenate([[0.0], np.cumsum([stations.ds[stations.section == i].sum()
                                              for i in range(layout.sections)])])
    centers, radii = np.zeros((k, 2 * count, 2)), np.zeros((k, 2 * count))
    for c_index, c in enumerate(layout.chambers):
        at = np.array([c.distance_mm * np.cos(c.angle), c.distance_mm * np.sin(c.angle)])
        centers[:, c_index] = centers[:, count + c_index] = at
        own = (stations.section == c.section) & stations.chamber
        radii[own, c_index] = 0.5 * c.diameter_mm
        chamber_start = starts[c.section] + layout.spec.end_wall_mm
        radii[stations.s < chamber_start, count + c_index] = 0.5 * layout.spec.feed_diameter_mm
    channels = np.concatenate([np.arange(count), np.arange(count)])
    return rod_body(stations.ds, stations.section, outlines, Cavities(centers, radii, channels), setup.modulus_kpa,
                    setup.backbone)


def per_chamber_rows(rows: list[dict[str, Any]], body: RodBody, rest: FloatArray) -> None:
    """Put each chamber's pressure (kPa) into the table's rows: the rod model's inverse on each section's best arc
    at that q.  ConfigError when a pressure would have to be negative (``backbone: free``), naming section and q."""
    for q in sorted({r["q"] for r in rows}):
        at_q = sorted((r for r in rows if r["q"] == q), key=lambda r: (r["section"], r["chamber"]))
        arcs = {r["section"]: r for r in at_q}
        n = len(arcs)
        rotation = np.array([[a["arc_kappa"] * a["arc_length_mm"] * np.cos(a["arc_phi"]),
                              a["arc_kappa"] * a["arc_length_mm"] * np.sin(a["arc_phi"])]
                             for a in (arcs[i + 1] for i in range(n))])
        stretch = (np.array([arcs[i + 1]["arc_length_mm"] for i in range(n)]) - rest
                   if body.backbone == "free" else None)
        pressures = per_chamber_pressures(body, rotation, stretch)
        if np.min(pressures) < -1e-9 * max(1.0, float(np.max(np.abs(pressures)))):
            c = int(np.argmin(pressures))
            raise ConfigError(
                f"actuation (supply: per_chamber, backbone: free): at q = {q:g} section {c // 3 + 1} chamber "
                f"{c % 3 + 1} would need {pressures[c]:.4g} kPa (a suction): a free backbone lengthens under every "
                "pressure, and this section must bend without lengthening; use actuation.backbone: inextensible")
        for r in at_q:
            r["pressure_kpa"] = max(float(pressures[3 * (r["section"] - 1) + r["chamber"] - 1]), 0.0)
