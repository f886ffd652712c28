"""``metrics.feasibility`` of two builds compared: stretches, wall thickness, rho * kappa and the verdict.

Stretches (dimensionless) are compared within ``STRETCH_TOL``, ten times the
tolerance to which the build converges them, so that grid noise never fails a
check; walls (mm) within the check's distance tolerance; per export q, matched
by q.  A reference without the block (built before softdesign judged
feasibility) gives a note, not a failure; a build without it where the
reference has one fails.
"""

from __future__ import annotations

from typing import Any

from softdesign.meshing.body.skin_stretch import STRETCH_TOL as CONVERGENCE_TOL
from softdesign.regression.figures import Figure, missing_figure, scalar_figure

#: Largest change of a stretch figure between two builds that counts as the same.
STRETCH_TOL = 10 * CONVERGENCE_TOL
#: Largest change of rho * kappa (dimensionless).
RHO_KAPPA_TOL = 1e-6
ITEM = "feasibility"


def _block(manifest: dict) -> dict[str, Any] | None:
    metrics = manifest.get("metrics")
    block = metrics.get(ITEM) if isinstance(metrics, dict) else None
    return block if isinstance(block, dict) else None


def compare_feasibility(build: dict, reference: dict, distance_mm: float, notes: list[str]) -> list[Figure]:
    """Figures of ``metrics.feasibility``: build minus reference, each within its tolerance."""
    ours, theirs = _block(build), _block(reference)
    if theirs is None:
        if ours is not None:
            notes.append("the reference has no metrics.feasibility (built before it existed): not compared")
        return []
    if ours is None:
        return [missing_figure(ITEM, "metrics.feasibility", in_build=False)]
    figures = []
    rows = {round(float(r["q"]), 6): r for r in ours.get("per_q", [])}
    for ref in theirs.get("per_q", []):
        q = round(float(ref["q"]), 6)
        row = rows.get(q)
        if row is None:
            figures.append(missing_figure(ITEM, f"q={q:.3f}", in_build=False))
            continue
        for key, tol in (("stretch_max", STRETCH_TOL), ("stretch_min", STRETCH_TOL),
                         ("rho_kappa_max", RHO_KAPPA_TOL), ("wall_min_mm", distance_mm), ("port_wall_mm", distance_mm)):
            if key in row or key in ref:
                figures.append(scalar_figure(ITEM, f"q={q:.3f} {key}", row.get(key), ref.get(key), tol))
    for key in ("stretch_max", "stretch_min"):
        value = ours.get("morph", {}).get(key, {}).get("value")
        figures.append(scalar_figure(ITEM, f"morph {key}", value,
                                     theirs.get("morph", {}).get(key, {}).get("value"), STRETCH_TOL))
    same = ours.get("feasible") == theirs.get("feasible")
    figures.append(Figure(ITEM, "feasible", None, None, same, str(ours.get("feasible")), str(theirs.get("feasible"))))
    return figures
