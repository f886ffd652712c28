"""Figure: a build's simulated sections -- deformed centerline against the designed arc, pressures over q, convergence.

Drawn from the simulate stage's figures (the manifest's ``metrics.simulate``,
:mod:`softdesign.pipeline.stages.simulate`); None when the build has none.

Top row, one panel per simulated section (the first ``MAX_SECTIONS``), at
its largest simulated q: the finite-element centerline (points) and the
designed arc at that q (dashed) in the designed arc's bending plane (the
component along its phi against the axial one, mm, the section's base frame).
Bottom left: every chamber's estimated pressure against q, one colour per
section (chamber 1 solid, 2 dashed, 3 dotted).  Bottom right: the residual
of every Newton iteration of each solve's final forward solve, load step
after load step (a new line per load step), on a log scale.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from softdesign.kinematics.pcc import tip_position_from_arc
from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture, link_colours, new_figure, picture

NAME = "simulate.png"
SIZE_IN = (12.0, 7.5)
#: Sections drawn across (the first ones; the caption says when more were solved).
MAX_SECTIONS = 6
#: Points of a drawn arc.
ARC_POINTS = 50


def simulate_block(data: BuildData) -> dict[str, Any] | None:
    """The simulate stage's figures in the manifest, or None."""
    block = data.manifest.get("metrics", {}).get("simulate")
    return block if isinstance(block, dict) and block.get("solves") else None


def _in_plane(points: np.ndarray, phi: float) -> tuple[np.ndarray, np.ndarray]:
    return points[:, 0] * np.cos(phi) + points[:, 1] * np.sin(phi), points[:, 2]


def _shape(ax: Any, solve: dict[str, Any], colour: Any) -> None:
    """One section's deformed centerline against its designed arc at the solve's q."""
    t = solve["target"]
    phi = t["phi_rad"]
    centerline = np.asarray(solve["deformed_centerline_mm"], float)
    lateral, axial = _in_plane(centerline - centerline[0], phi)
    ax.plot(lateral, axial, "o", ms=2.5, color=colour, label="FE centerline")
    designed = tip_position_from_arc(t["kappa_per_mm"], phi, t["length_mm"] * np.linspace(0.0, 1.0, ARC_POINTS))
    ax.plot(*_in_plane(designed, phi), "--", color="#333333", lw=1.0, label="designed arc")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"section {solve['section']}, q = {solve['q']:g}: error "
                 f"{math.hypot(*t['error_mm']):.2f} mm", fontsize=8)
    ax.set_xlabel(f"along phi = {math.degrees(phi):.0f} deg, mm", fontsize=7)
    ax.tick_params(labelsize=6)


def _pressures(ax: Any, solves: list[dict[str, Any]], colours: list[Any], sections: list[int]) -> None:
    for k, section in enumerate(sections):
        own = sorted((s for s in solves if s["section"] == section), key=lambda s: s["q"])
        for j in range(len(own[0]["pressures_kpa"])):
            ax.plot([s["q"] for s in own], [s["pressures_kpa"][j] for s in own], "o", ls=("-", "--", ":")[j % 3],
                    color=colours[k], ms=3, lw=1.0, label=f"section {section}" if j == 0 else None)
    ax.set_xlabel("q")
    ax.set_ylabel("estimated pressure, kPa")
    ax.set_title("pressures against q (chamber 1 solid, 2 dashed, 3 dotted)")
    ax.legend(fontsize=7)


def _convergence(ax: Any, solves: list[dict[str, Any]], colours: list[Any], sections: list[int]) -> None:
    for solve in solves:
        colour = colours[sections.index(solve["section"])]
        first = 1
        for step in solve["convergence"]:
            residuals = step["residuals_mN"]
            ax.semilogy(np.arange(first, first + len(residuals)), np.maximum(residuals, 1e-300), "o-", ms=2.5,
                        lw=0.8, color=colour)
            first += len(residuals)
    ax.set_xlabel("Newton iteration (load steps one after the other, a line each)")
    ax.set_ylabel("free residual, mN")
    ax.set_title("convergence of each solve at its pressures")


def simulate_picture(data: BuildData) -> Picture | None:
    """The figure, or None when the build has no simulation."""
    block = simulate_block(data)
    if block is None:
        return None
    solves = block["solves"]
    sections = sorted({s["section"] for s in solves})
    colours = link_colours(max(sections))
    colours = [colours[i - 1] for i in sections]
    shown = sections[:MAX_SECTIONS]
    figure = new_figure(SIZE_IN)
    grid = figure.add_gridspec(2, max(len(shown), 2))
    for k, section in enumerate(shown):
        last = max((s for s in solves if s["section"] == section), key=lambda s: s["q"])
        _shape(figure.add_subplot(grid[0, k] if len(shown) > 1 else grid[0, :]), last, colours[k])
    half = max(len(shown), 2) // 2
    _pressures(figure.add_subplot(grid[1, :half]), solves, colours, sections)
    _convergence(figure.add_subplot(grid[1, half:]), solves, colours, sections)
    worst = max(solves, key=lambda s: s["max_stress_kpa"])
    strength = worst["tensile_strength_kpa"]
    versus = f" against a tensile strength of {strength:.0f} kPa" if strength else ""
    unconverged = [f"section {s['section']} q = {s['q']:g}" for s in solves if not s["target"]["converged"]]
    caption = (f"Model estimates: {solves[0]['source']}. Each section alone, its base clamped, the chambers' "
               "pressures following the deformed walls; the pressures are those whose best arc comes closest to "
               "the designed arc (the error: L/2 times the bending vector's error and the length's, mm). Largest "
               f"principal stress {worst['max_stress_kpa']:.0f} kPa (section {worst['section']}){versus}."
               + (f" Searches stopped above their tolerance: {', '.join(unconverged)}." if unconverged else "")
               + (f" First {len(shown)} of {len(sections)} sections drawn." if len(shown) < len(sections) else "")
               + " Leaves out: " + "; ".join(block["leaves_out"]) + ".")
    return picture(NAME, figure, SIZE_IN, "Simulated sections: shape, pressures, convergence", caption)
