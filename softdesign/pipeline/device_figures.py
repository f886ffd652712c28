"""The whole device's finite-element figures beside the design and the rod model, as JSON and as text.

- **Against the designed chain**: the body's centerline at q (``blend: pcc``:
  the designed constant-curvature chain at q), the largest distance from the
  deformed centerline to it, the tip's distance and the angle between the
  tip tangents; each section's best arc at q
  (:func:`~softdesign.kinematics.pcc_fit.fit_links`, in the section's base frame).
- **Against the rod model** (``supply: single``, :mod:`softdesign.pipeline.rod_single`
  at the same pressure): the same three figures, and its arcs; ``per_chamber``:
  its arcs (the rod model's inverse gave the pressures).
- The largest stretch and stress (with the section and the place) against the
  material's ``max_stretch`` and tensile strength; the thread's largest tension
  against its limit (breaking load over the safety factor) and the rod model's
  ``P r pitch``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.types import FloatArray

#: The designed centerline is compared as a polyline of this many points (its chord error is far below 1 um).
DESIGN_POINTS = 4001
#: What the whole-device model leaves out, stated with every answer.
LEAVES_OUT = (
    "contact with the vessel wall",
    "viscoelasticity (the answer is the static, long-time equilibrium)",
    "the Mullins effect (softening after the first loading)",
    "the supply line from the base face into section 1's chamber and the channels joining consecutive chambers "
    "(supply: single), and the body's slanted end cuts",
)


def polyline_distances(points: FloatArray, line: FloatArray) -> FloatArray:
    """Each point's (m, 3) distance (m,) mm to the polyline ``line`` (k, 3), segment by segment."""
    a, b = line[:-1], line[1:]
    ab = b - a
    t = np.einsum("mki,ki->mk", points[:, None, :] - a[None], ab) / np.maximum(np.einsum("ki,ki->k", ab, ab), 1e-300)
    feet = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - feet, axis=2).min(axis=1)


def versus(centerline: FloatArray, tip_frame: FloatArray, line: FloatArray, tip: FloatArray) -> dict[str, float]:
    """The deformed centerline and tip frame (4, 4) against another shape: its polyline and tip frame (4, 4)."""
    cosine = float(np.clip(tip_frame[:3, 2] @ tip[:3, 2], -1.0, 1.0))
    return {"max_mm": float(polyline_distances(centerline, line).max()),
            "tip_mm": float(np.linalg.norm(tip_frame[:3, 3] - tip[:3, 3])), "tip_angle_rad": float(np.arccos(cosine))}


def designed_shape(outcome: Any, q: float) -> tuple[FloatArray, FloatArray, list[dict[str, float]]]:
    """The body's centerline at q (k, 3), its tip frame (4, 4) and each section's best arc at q."""
    from softdesign.kinematics.pcc_fit import fit_links
    from softdesign.pipeline.stages.actuation import ARC_SAMPLES

    chain = outcome.results["kinematics"].chain
    curve = chain.shape.curve_at(q)
    tip = np.eye(4)
    tip[:3, :3], tip[:3, 3] = curve.frames([1.0])[0], curve.points([1.0])[0]
    arcs = [{"kappa": a.kappa, "phi": a.phi, "length": a.length} for a in fit_links(chain, q, ARC_SAMPLES)]
    return curve.points(np.linspace(0.0, 1.0, DESIGN_POINTS)), tip, arcs


def rod_shape(outcome: Any, pressure_kpa: float) -> tuple[FloatArray, FloatArray, list[dict[str, float]]]:
    """``supply: single``'s rod model at one pressure: its centerline (k, 3), tip pose (4, 4) and section arcs."""
    from softdesign.kinematics.rod import section_arcs, station_poses, strains
    from softdesign.pipeline.rod_device import rod_setup
    from softdesign.pipeline.rod_single import size_case

    case, results = outcome.case, outcome.results
    design = results["design"]
    setup = rod_setup(case)
    if isinstance(setup, str):
        raise ConfigError(f"simulate --all: {setup}")
    single = size_case(case, results["kinematics"], results["fit"], design, setup)
    body = single.device.body
    eps0, w, _ = strains(body, [pressure_kpa])
    poses = station_poses(eps0, w, body.ds, design.base2world)
    kappa, phi, length = section_arcs(body, poses, eps0)
    arcs = [{"kappa": float(k), "phi": float(p), "length": float(s)} for k, p, s in zip(kappa, phi, length,
                                                                                          strict=True)]
    return poses[:, :3, 3], poses[-1], arcs


def _rod(outcome: Any, q: float, pressures: list[float]) -> tuple[dict[str, Any] | None, list[dict[str, float]]]:
    """The rod model's shape figures (None: per_chamber) and its arcs at the solve's pressures."""
    from softdesign.pipeline.rod_pressure import pressure_document

    if outcome.case.actuation.supply == "single":
        line, tip, arcs = rod_shape(outcome, pressures[0])
        return {"line": line, "tip": tip}, arcs
    document = pressure_document(outcome, q, None)
    return None, [{k: s[k] for k in ("kappa", "phi", "length")} for s in document["sections"]]


def _extreme(e: Any) -> dict[str, Any]:
    return {"value": e.value, "section": e.section + 1, "at_mm": np.round(e.at, 4).tolist()}


def _thread(outcome: Any, extreme: Any, pressures: list[float], top: float | None, ends: str | None = None
            ) -> dict[str, Any] | None:
    """A thread's largest tension (N) against its limit and, for the hoop thread of a single supply (``top``: P*),
    the rod model's tension per turn P r pitch; ``ends``: the hoop thread's chamber ends (bare, or patched: the
    largest tension is then over the winding and the patches)."""
    if extreme is None:
        return None
    summary = outcome.results["actuation"].summary
    limit = summary.get("tension_limit_n")
    rod = None
    if top:
        rod = max(c["tension_per_turn_n"] for s in summary["sections"] for c in s["chambers"]) * pressures[0] / top
    value = extreme.value * 1e-3
    return {**_extreme(extreme), "value": value, "unit": "N", "limit_n": limit,
            "fraction_of_limit": None if not limit else value / limit, "rod_model_n": rod,
            "ends": ends}


def device_payload(outcome: Any, o: Any, device: Any, material: Any, loads: tuple[float, list[float], float | None],
                   answer: dict[str, Any], times: dict[str, float]) -> dict[str, Any]:
    """The JSON-ready figures of a whole-device solve (``simulate --all --json``).

    A solve that stopped short (``answer["load_factor"]`` below 1) is measured at the largest load it held:
    ``reached`` says where (load factor, q, pressures) and why, and the figures compare the design and the rod
    model at that q; ``reached`` is None when the asked load was reached.
    """
    from softdesign.pipeline.simulate_run import quadratic_node_count

    q, pressures, top = loads
    figures, record = answer["figures"], answer["record"]
    t = float(answer.get("load_factor", 1.0))
    held_q, held = t * q, [t * p for p in pressures]  # where the figures are: the asked load, or the largest held
    line, tip, designed = designed_shape(outcome, held_q)
    rod, rod_arcs = _rod(outcome, held_q, held)
    sections = [{"section": i + 1, "kappa": a.kappa, "phi": a.phi, "length": a.length, "misfit_max_mm": a.misfit_max_mm,
                 "designed": designed[i], "rod_model": rod_arcs[i]} for i, a in enumerate(figures.arcs)]
    return {
        "supply": outcome.case.actuation.supply, "q": q,
        "pressure_kpa": pressures[0] if top else None, "design_pressure_kpa": top, "pressures_kpa": pressures,
        "reached": None if t >= 1.0 else {"load_factor": t, "q": held_q, "pressure_kpa": held[0] if top else None,
                                          "pressures_kpa": held, "stopped_because": answer["stopped_because"]},
        "mesh": {"sections": len(device.parts), "nodes": len(device.whole.points), "tets": len(device.whole.tets),
                 "quadratic_nodes": quadratic_node_count(device.whole), "size_mm": o.size_mm,
                 "layer_mm": o.layer_mm, "angular_count": o.angular_count},
        "material": {"name": material.name, "law": material.law.kind, "mu_kpa": material.law.mu_kpa},
        "centerline": np.round(figures.centerline, 6).tolist(),
        "centerline_frame": "the case's frame (its input files' coordinates), mm, base to tip",
        "tip_frame": np.round(figures.tip_frame, 9).tolist(),
        "versus_design": versus(figures.centerline, figures.tip_frame, line, tip),
        "versus_rod_model": None if rod is None else versus(figures.centerline, figures.tip_frame, rod["line"],
                                                            rod["tip"]),
        "sections": sections,
        "max_stretch": {**_extreme(figures.stretch), "limit": material.max_stretch},
        "max_stress_kpa": {**_extreme(figures.stress), "tensile_strength_kpa": material.tensile_strength_kpa},
        "thread": _thread(outcome, figures.thread, pressures, top, outcome.case.chamber_ends),
        "backbone_thread": _thread(outcome, figures.backbone, pressures, None),
        "tie_gap_mm": figures.tie_gap_mm,
        "convergence": [{"load_factor": t, "iterations": n, "residuals_mN": h}
                        for t, n, h in zip(record.load_factors, record.iterations, record.residuals, strict=True)],
        "seconds": {k: round(v, 2) for k, v in times.items()},
        "leaves_out": list(LEAVES_OUT) + [note for part in device.parts for note in part.notes],
    }


def device_lines(payload: dict[str, Any]) -> list[str]:
    """The payload as the terminal's lines."""
    m, d, r = payload["mesh"], payload["versus_design"], payload["versus_rod_model"]
    load = (f"P = {payload['pressure_kpa']:.4g} kPa (q = {payload['q']:.4g} of P* {payload['design_pressure_kpa']:.4g})"
            if payload["design_pressure_kpa"] else f"the rod model's pressures at q = {payload['q']:g}")
    lines = [f"whole device: {m['sections']} sections, {m['quadratic_nodes']} nodes, {m['tets']} tets, "
             f"{payload['material']['name']}, {load}"]
    held = payload.get("reached")
    if held is not None:
        at = (f"{held['pressure_kpa']:.4g} kPa" if held["pressure_kpa"] is not None
              else f"{held['load_factor']:.4g} of the pressures")
        lines.append(f"NOT REACHED: no equilibrium was found past {at} (load factor {held['load_factor']:.4g}, "
                     f"q = {held['q']:.4g}); the figures below are there, against the design and the rod model at "
                     "that q")
    lines.append(versus_line("designed chain", d))
    if r is not None:
        lines.append(versus_line("rod model", r))
    for s in payload["sections"]:
        lines.append(f"  section {s['section']}: kappa {s['kappa']:.5g} 1/mm (design {s['designed']['kappa']:.5g}, "
                     f"rod {s['rod_model']['kappa']:.5g}), phi {np.degrees(s['phi']):.2f} deg (design "
                     f"{np.degrees(s['designed']['phi']):.2f}), L {s['length']:.3f} mm (design "
                     f"{s['designed']['length']:.3f}), arc misfit {s['misfit_max_mm']:.3f} mm")
    lines += _limit_lines(payload)
    sec = payload["seconds"]
    lines.append(f"times: mesh {sec['mesh_s']:.1f} s, solve {sec['solve_s']:.1f} s wall ({sec['solve_cpu_s']:.1f} s "
                 f"CPU), {len(payload['convergence'])} steps; joints' largest gap {payload['tie_gap_mm']:.2g} mm")
    return lines


def versus_line(what: str, v: dict[str, float]) -> str:
    return (f"against the {what}: within {v['max_mm']:.3f} mm, tip {v['tip_mm']:.3f} mm and "
            f"{np.degrees(v['tip_angle_rad']):.2f} deg off")


def _limit_lines(payload: dict[str, Any]) -> list[str]:
    s, p = payload["max_stretch"], payload["max_stress_kpa"]
    stretch_limit = f" (max_stretch {s['limit']:g})" if s["limit"] else ""
    strength = f" (tensile strength {p['tensile_strength_kpa']:.0f} kPa)" if p["tensile_strength_kpa"] else ""
    lines = [f"largest stretch {s['value']:.4f} in section {s['section']} at {s['at_mm']} mm{stretch_limit}",
             f"largest principal stress {p['value']:.1f} kPa in section {p['section']} at {p['at_mm']} mm{strength}"]
    for key, what in (("thread", "hoop thread"), ("backbone_thread", "backbone thread")):
        t = payload[key]
        if t is None:
            continue
        limit = f" of {t['limit_n']:.3g} N limit ({100 * t['fraction_of_limit']:.1f} %)" if t["limit_n"] else ""
        rod = f"; rod model P r pitch {t['rod_model_n']:.3g} N per turn" if t["rod_model_n"] is not None else ""
        what = "hoop thread (winding and end patches)" if t.get("ends") == "patch" else what
        lines.append(f"{what} tension {t['value']:.3g} N in section {t['section']}{limit}{rod}")
    return lines
