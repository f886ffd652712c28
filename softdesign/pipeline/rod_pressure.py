"""``softdesign pressure``: the rod model's shape, chamber lengths and deviation at one q or one pressure.

The stages through ``fit`` run (cached in the build folder); the chambers are sized as the build sizes them
(:mod:`softdesign.pipeline.rod_single`) and the rod model is evaluated at ``q P*`` (``supply: single``), or its
inverse gives every chamber's pressure at q (``per_chamber``).  No meshes, no walls measured on meshes.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import section_arcs, station_poses, strains

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.pipeline.api import BuildOutcome
    from softdesign.pipeline.rod_device import RodSetup


def check_pressure_case(case: Case, pressure_kpa: float | None) -> RodSetup:
    """The rod model's numbers for ``softdesign pressure``, or ConfigError (before any stage runs) saying why not."""
    from softdesign.pipeline.rod_device import rod_setup

    if case.actuation is None:
        raise ConfigError("pressure: the case has no actuation: block (the chambers the rod model pressurises)")
    setup = rod_setup(case)
    if isinstance(setup, str):
        raise ConfigError(f"pressure: {setup}")
    if pressure_kpa is not None and case.actuation.supply != "single":
        raise ConfigError("pressure: --pressure is one supply pressure (actuation.supply: single); this case has a "
                          "pressure per chamber: give --q")
    return setup


def pressure_document(outcome: BuildOutcome, q: float | None, pressure_kpa: float | None) -> dict[str, Any]:
    """The rod model at ``q`` (or one supply pressure): JSON-ready (see ``softdesign pressure --help``)."""
    case = outcome.case
    setup = check_pressure_case(case, pressure_kpa)
    start = time.perf_counter()
    if case.actuation is not None and case.actuation.supply == "single":
        document = _single(outcome, setup, q, pressure_kpa)
    else:
        document = _per_chamber(outcome, setup, 1.0 if q is None else q)
    document["seconds"] = time.perf_counter() - start
    return document


def _single(outcome: BuildOutcome, setup: RodSetup, q: float | None, pressure_kpa: float | None) -> dict[str, Any]:
    from softdesign.pipeline.rod_single import chain_deviation_mm, chamber_lengths_mm, size_case

    results = outcome.results
    design = results["design"]
    single = size_case(outcome.case, results["kinematics"], results["fit"], design, setup)
    top = single.device.pressure_kpa
    if pressure_kpa is not None:
        q = pressure_kpa / top
    q = 1.0 if q is None else q
    p = q * top
    body = single.device.body
    eps0, w, _ = strains(body, [p])
    poses = station_poses(eps0, w, body.ds, design.base2world)
    kappa, phi, length = section_arcs(body, poses, eps0)
    return {
        "supply": "single", "design_pressure_kpa": top, "pressure_kpa": p, "q": q,
        "sections": [{"section": i + 1, "kappa": float(kappa[i]), "phi": float(phi[i]), "length": float(length[i])}
                     for i in range(len(kappa))],
        "chamber_lengths_mm": chamber_lengths_mm(single, p).tolist(),
        "deviation_mm": chain_deviation_mm(body, p, design, q),
        "centerline": poses[:, :3, 3].tolist(),
        "deviation_of": "the designed chain with each section's curvature times q (blend: pcc)",
    }


def _per_chamber(outcome: BuildOutcome, setup: RodSetup, q: float) -> dict[str, Any]:
    from softdesign.pipeline.rod_device import (
        layout_body,
        layout_stations,
        outlines_at,
        per_chamber_rows,
        section_rest_lengths,
    )
    from softdesign.pipeline.stages.actuation import _rows_at, actuation_layout

    kinematics, fit = outcome.results["kinematics"], outcome.results["fit"]
    layout = actuation_layout(outcome.case, kinematics)
    if layout is None:
        raise ConfigError("pressure: the case has no actuation: block")
    rest = section_rest_lengths(kinematics)
    stations = layout_stations(layout, rest)
    body = layout_body(layout, stations, outlines_at(kinematics, fit, stations.s), setup)
    rows = _rows_at(kinematics, layout, q, True, None)[0]
    per_chamber_rows(rows, body, rest)
    pressures = np.array([r["pressure_kpa"] for r in rows], float).reshape(layout.sections, -1)
    eps0, w, _ = strains(body, pressures.reshape(-1))
    poses = station_poses(eps0, w, body.ds, np.eye(4))
    kappa, phi, length = section_arcs(body, poses, eps0)
    return {
        "supply": "per_chamber", "q": q, "pressures_kpa": pressures.tolist(),
        "sections": [{"section": i + 1, "kappa": float(kappa[i]), "phi": float(phi[i]), "length": float(length[i]),
                      "target": {"kappa": rows[3 * i]["arc_kappa"], "phi": rows[3 * i]["arc_phi"],
                                 "length": rows[3 * i]["arc_length_mm"]}} for i in range(len(kappa))],
        "chamber_lengths_mm": [[r["length_mm"] for r in rows if r["section"] == i + 1]
                               for i in range(layout.sections)],
    }
