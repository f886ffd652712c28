"""``softdesign pressure``: the rod model's shape, chamber lengths and deviation at one q or one pressure.

From the build's rod file (:mod:`softdesign.pipeline.rod_file`): ``supply: single`` evaluates the rod model at
``q P*``, ``per_chamber`` its inverse at a q of the build's grid (every chamber's pressure).  Only numpy and the
rod model are imported: milliseconds.  A per-chamber q off the build's grid runs the stages through ``fit``
(cached in the build folder) and sizes as the build does (:func:`pressure_document`): seconds.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import section_arcs, station_poses, strains
from softdesign.pipeline.rod_evaluate import per_chamber_from_rod, single_from_rod
from softdesign.pipeline.rod_file import read_rod, rod_of_unchanged_build

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.pipeline.rod_device import RodSetup



class Built(Protocol):
    """What the per-chamber answer reads of a run: its case and each stage's result (a
    :class:`~softdesign.pipeline.api.BuildOutcome`, or the device stage's own; not imported, so that stages can
    call this module without an import running up to the API)."""

    @property
    def case(self) -> Case: ...

    @property
    def results(self) -> dict[str, Any]: ...


def check_pressure_case(case: Case, pressure_kpa: float | None) -> None:
    """ConfigError (before any file is read) when ``softdesign pressure`` cannot answer for this case."""
    if case.actuation is None:
        raise ConfigError("pressure: the case has no actuation: block (the chambers the rod model pressurises)")
    if case.actuation.reinforcement.kind == "none" or case.material is None:
        from softdesign.pipeline.rod_device import rod_setup

        setup = rod_setup(case)
        if isinstance(setup, str):
            raise ConfigError(f"pressure: {setup}")
    if pressure_kpa is not None and case.actuation.supply != "single":
        raise ConfigError("pressure: --pressure is one supply pressure (actuation.supply: single); this case has a "
                          "pressure per chamber: give --q")


def pressure_from_build(case: Case, case_file: str, out: Path | None, q: float | None,
                        pressure_kpa: float | None) -> dict[str, Any] | None:
    """The answer from the build's rod file (ConfigError when there is none, or it is not this case's); None for a
    per-chamber q off the build's grid (the caller then runs the stages through fit)."""
    build_dir = out if out is not None else Path("build") / case.name
    return _answer_from_rod(read_rod(case, build_dir, case_file), q, pressure_kpa)


def answer_if_unchanged(case_file: str | Path, out: Path | None, q: float | None,
                        pressure_kpa: float | None) -> dict[str, Any] | None:
    """The answer from the build's rod file when the case file and its inputs are those the build was made from
    (:func:`~softdesign.pipeline.rod_file.rod_of_unchanged_build`), without loading the case; None otherwise, and
    for what the rod file cannot answer alone (``--pressure`` on a per-chamber case, a q off the build's grid)."""
    rod = rod_of_unchanged_build(case_file, out)
    return None if rod is None else _answer_from_rod(rod, q, pressure_kpa)


def _answer_from_rod(rod: dict[str, Any], q: float | None, pressure_kpa: float | None) -> dict[str, Any] | None:
    """The rod file's answer, ``seconds`` the model's time; None for what it cannot answer alone: ``--pressure``
    on a per-chamber case (the full path refuses it, naming the case's supply) or a q off the build's grid."""
    start = time.perf_counter()
    if rod["supply"] == "single":
        document = single_from_rod(rod, q, pressure_kpa)
    elif pressure_kpa is not None:
        return None
    else:
        found = per_chamber_from_rod(rod, 1.0 if q is None else q)
        if found is None:
            return None
        document = found
    document["seconds"] = time.perf_counter() - start
    return document


def pressure_document(outcome: Built, q: float | None, pressure_kpa: float | None) -> dict[str, Any]:
    """The per-chamber rod model at a ``q`` off the build's grid, from the stages through fit: JSON-ready (see
    ``softdesign pressure --help``; a single supply is always answered from its rod file)."""
    from softdesign.pipeline.rod_device import rod_setup

    case = outcome.case
    check_pressure_case(case, pressure_kpa)
    setup = rod_setup(case)
    if isinstance(setup, str):
        raise ConfigError(f"pressure: {setup}")
    start = time.perf_counter()
    document = _per_chamber(outcome, setup, 1.0 if q is None else q)
    document["seconds"] = time.perf_counter() - start
    return document


def _per_chamber(outcome: Built, setup: RodSetup, q: float) -> dict[str, Any]:
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
