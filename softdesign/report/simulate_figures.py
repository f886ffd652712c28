"""The figure of one section's solve: its deformed centerline against its best (and designed) arc, and convergence.

Left: the centerline in its bending plane (the component along phi against
the axial one, mm), with the best arc through it and, for ``--target``, the
designed arc.  Right: the residual of every Newton iteration, one line per
load step, on a log scale.  Drawn from the JSON figures of
:func:`softdesign.pipeline.simulate_run.payload`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.kinematics.pcc import tip_position_from_arc
from softdesign.report.plotting import new_figure, png_bytes, styled

#: Figure size, inches.
SIZE_IN = (7.0, 3.0)
#: Points of a drawn arc.
ARC_POINTS = 50


def _in_plane(points: np.ndarray, phi: float) -> tuple[np.ndarray, np.ndarray]:
    return points[:, 0] * np.cos(phi) + points[:, 1] * np.sin(phi), points[:, 2]


def simulate_figure_png(payload: dict[str, Any]) -> bytes:
    """PNG bytes of the figure of one solve's ``payload``."""
    figure = new_figure(SIZE_IN)
    with styled():
        shape, steps = figure.subplots(1, 2)
        arc = payload["arc"]
        phi = arc["phi_rad"]
        centerline = np.asarray(payload["deformed_centerline_mm"], float)
        s = np.linspace(0.0, 1.0, ARC_POINTS)
        lateral, axial = _in_plane(centerline, phi)
        shape.plot(lateral, axial, "o", ms=3, label="FE centerline")
        best = tip_position_from_arc(arc["kappa_per_mm"], phi, arc["length_mm"] * s)
        shape.plot(*_in_plane(best, phi), "-", label="best arc")
        if "target" in payload:
            t = payload["target"]
            designed = tip_position_from_arc(t["kappa_per_mm"], t["phi_rad"], t["length_mm"] * s)
            shape.plot(*_in_plane(designed, phi), "--", label=f"designed arc, q = {t['q']:g}")
        shape.set_xlabel(f"along phi = {np.degrees(phi):.1f} deg, mm")
        shape.set_ylabel("along the base tangent, mm")
        pressures = ", ".join(f"{p:.1f}" for p in payload["pressures_kpa"])
        shape.set_title(f"section {payload['section']}: {pressures} kPa")
        shape.legend(loc="best")
        for k, step in enumerate(payload["convergence"], start=1):
            steps.semilogy(np.arange(1, len(step["residuals_mN"]) + 1), step["residuals_mN"], "o-", ms=3,
                           label=f"step {k} (load {step['load_factor']:.2f})")
        steps.set_xlabel("Newton iteration")
        steps.set_ylabel("free residual, mN")
        steps.set_title("convergence")
        steps.legend(loc="best")
    return png_bytes(figure)
