"""The rod model evaluated from a build's rod file (:mod:`softdesign.pipeline.rod_file`): the shape, the chamber
lengths and the distance from the designed chain at one pressure, or the per-chamber inverse at a grid q.

Used by the build (:mod:`softdesign.pipeline.rod_single`) and by ``softdesign pressure``; imports numpy and the
rod model only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import RodBody, section_arcs, station_poses, strains
from softdesign.pipeline.rod_file import body_from
from softdesign.types import FloatArray

#: A q given on the command line is the build's grid q within this (the grid's q are written as repr floats).
GRID_Q_ATOL = 1e-12


def chain_deviation(body: RodBody, pressure_kpa: float, base2world: FloatArray, w: FloatArray, lengths: FloatArray,
                    q: float, rest: FloatArray | None = None) -> float:
    """Largest true distance (mm) from the rod model's centreline at ``pressure_kpa`` to the designed chain at q
    (``blend: pcc``: each section's curvature ``w`` (n, 2) 1/mm times q, ``lengths`` (n,) mm), the stations' ends
    and the tip.  ``rest`` (n,) mm: a free backbone's rest lengths, the chain at q then the rest-length morph's
    (:func:`~softdesign.pipeline.rod_free.morph_chain`)."""
    from softdesign.kinematics.pcc_chain import feet_on_chain, section_poses
    from softdesign.pipeline.rod_free import morph_chain

    eps0, bend, _ = strains(body, [pressure_kpa])
    poses = station_poses(eps0, bend, body.ds, base2world)
    w_q, lengths_q = (q * np.asarray(w, float), np.asarray(lengths, float)) if rest is None else morph_chain(
        w, lengths, rest, q)
    bases, _ = section_poses(base2world, w_q, lengths_q)
    _, distance, _ = feet_on_chain(poses[:, :3, 3], bases, w_q, lengths_q)
    return float(np.max(distance))


def chamber_axis_lengths(body: RodBody, pressure_kpa: float, distance_mm: FloatArray, angle: FloatArray,
                         chamber: np.ndarray) -> FloatArray:
    """Each section's chamber axis length (n,) mm at ``pressure_kpa``: ``sum ds (1 + eps0 - w . p)`` over the
    stations that hold it (``chamber`` (k,) bool; the chamber at ``distance_mm``, ``angle`` (k,))."""
    eps0, bend, _ = strains(body, [pressure_kpa])
    p = np.stack([distance_mm * np.cos(angle), distance_mm * np.sin(angle)], axis=1)
    along = body.ds * (1.0 + eps0 - np.einsum("ki,ki->k", bend, p))
    n = int(body.section.max()) + 1
    return np.array([along[(body.section == i) & chamber].sum() for i in range(n)])


def single_from_rod(rod: dict[str, Any], q: float | None, pressure_kpa: float | None) -> dict[str, Any]:
    """``supply: single`` at q (or one supply pressure) from a rod file: JSON-ready."""
    body, single = body_from(rod), rod["single"]
    top = float(single["design_pressure_kpa"])
    q = pressure_kpa / top if pressure_kpa is not None else (1.0 if q is None else q)
    p = q * top
    base2world, w, lengths = (np.asarray(single[k], float) for k in ("base2world", "w", "lengths"))
    eps0, bend, _ = strains(body, [p])
    poses = station_poses(eps0, bend, body.ds, base2world)
    kappa, phi, length = section_arcs(body, poses, eps0)
    chamber = np.asarray(rod["stations"]["chamber"], bool)
    return {
        "supply": "single", "design_pressure_kpa": top, "pressure_kpa": p, "q": q,
        "sections": [{"section": i + 1, "kappa": float(kappa[i]), "phi": float(phi[i]), "length": float(length[i])}
                     for i in range(len(kappa))],
        "chamber_lengths_mm": chamber_axis_lengths(body, p, np.asarray(single["distance_mm"], float),
                                                   np.asarray(single["angle"], float), chamber).tolist(),
        "deviation_mm": chain_deviation(body, p, base2world, w, lengths, q,
                                        None if single.get("rest_lengths") is None
                                        else np.asarray(single["rest_lengths"], float)),
        "centerline": poses[:, :3, 3].tolist(),
        "deviation_of": "the designed chain with each section's curvature times q (blend: pcc)",
    }


def per_chamber_from_rod(rod: dict[str, Any], q: float) -> dict[str, Any] | None:
    """``per_chamber`` at a q of the build's grid from a rod file (None when q is not on it): every chamber's
    pressure (the rod model's inverse on each section's best arc at q) and each section's arc."""
    from softdesign.kinematics.rod_inverse import per_chamber_pressures

    arcs = next((np.asarray(a, float) for at, a in rod["per_chamber"]["arcs"] if abs(at - q) <= GRID_Q_ATOL), None)
    if arcs is None:
        return None
    body = body_from(rod)
    rotation = (arcs[:, 0] * arcs[:, 2])[:, None] * np.stack([np.cos(arcs[:, 1]), np.sin(arcs[:, 1])], axis=1)
    rest = np.asarray(rod["per_chamber"]["rest_lengths_mm"], float)
    pressures = per_chamber_pressures(body, rotation, arcs[:, 2] - rest if body.backbone == "free" else None)
    if np.min(pressures) < -1e-9 * max(1.0, float(np.max(np.abs(pressures)))):
        c = int(np.argmin(pressures))
        raise ConfigError(f"pressure: at q = {q:g} section {c // 3 + 1} chamber {c % 3 + 1} would need "
                          f"{pressures[c]:.4g} kPa (a suction); use actuation.backbone: inextensible")
    pressures = np.maximum(pressures, 0.0)
    eps0, bend, _ = strains(body, pressures)
    kappa, phi, length = section_arcs(body, station_poses(eps0, bend, body.ds, np.eye(4)), eps0)
    return {
        "supply": "per_chamber", "q": q, "pressures_kpa": pressures.reshape(-1, 3).tolist(),
        "sections": [{"section": i + 1, "kappa": float(kappa[i]), "phi": float(phi[i]), "length": float(length[i]),
                      "target": {"kappa": float(arcs[i, 0]), "phi": float(arcs[i, 1]), "length": float(arcs[i, 2])}}
                     for i in range(len(kappa))],
        "chamber_lengths_mm": rod["per_chamber"]["chamber_lengths_mm"][_grid_index(rod, q)],
    }


def _grid_index(rod: dict[str, Any], q: float) -> int:
    return next(i for i, (at, _) in enumerate(rod["per_chamber"]["arcs"]) if abs(at - q) <= GRID_Q_ATOL)
