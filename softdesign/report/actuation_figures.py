"""Figure: an actuated body's cross-sections with chambers and feeds at q = 0 and 1, and chamber length over q.

Top two rows: the body's section in its (N, B) plane at the middle of each
section's chambers (at most ``MAX_SECTIONS`` sections), the skin rho(q, l, a) at
q = 0 and q = 1, each chamber (filled) and each feed passing there (outlined)
at its designed (distance, angle) and diameter; the sections' frames are the
body's RMF, so the same chamber sits at the same place at every q.  Bottom:
every chamber's length from ``actuation.csv`` (seed 003 on the section's best
arc) against q, one colour per section.  None when the build has no actuation.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture, link_colours, new_figure, picture

NAME = "actuation.png"
SIZE_IN = (12.0, 8.5)
#: Sections drawn across (the first ones; the caption says when more exist).
MAX_SECTIONS = 6
ANGLES = 180


def _summary(data: BuildData) -> dict[str, Any] | None:
    block = data.manifest.get("metrics", {}).get("actuation")
    return block if isinstance(block, dict) and block.get("rows") else None


def _section(ax, data: BuildData, block: dict[str, Any], section: int, q: float, colour) -> None:
    """One cross-section: skin, chambers of ``section`` and the feeds passing it, at the middle of its chambers."""
    from matplotlib.patches import Circle

    layout = block["layout"]
    own = [c for c in layout["chambers"] if c["section"] == section]
    l = 0.5 * (own[0]["l_start"] + own[0]["l_end"])
    a = np.linspace(0.0, 2.0 * np.pi, ANGLES, endpoint=False)
    assert data.fit is not None  # an actuated build has a fit
    rho = data.fit.field.evaluate_grid(q, np.array([l]), a)[0]
    ax.fill(rho * np.cos(a), rho * np.sin(a), color="#eeeeee", ec="#555555", lw=0.8)
    for c in own:
        t = np.deg2rad(c["angle_deg"])
        ax.add_patch(Circle((c["distance_mm"] * np.cos(t), c["distance_mm"] * np.sin(t)), c["diameter_mm"] / 2,
                            color=colour))
        ax.annotate(str(c["chamber"]), (c["distance_mm"] * np.cos(t), c["distance_mm"] * np.sin(t)), fontsize=6,
                    ha="center", va="center", color="white")
    for f in layout["feeds"]:
        if f["section"] > section:
            t = np.deg2rad(f["angle_deg"])
            ax.add_patch(Circle((f["ring_mm"] * np.cos(t), f["ring_mm"] * np.sin(t)), f["diameter_mm"] / 2,
                                fill=False, ec="#333333", lw=0.6))
    ax.plot([0, 0.6 * rho.max()], [0, 0], color="#d62728", lw=0.6)  # N
    ax.plot([0, 0], [0, 0.6 * rho.max()], color="#2ca02c", lw=0.6)  # B
    ax.set_aspect("equal")
    ax.set_title(f"section {section}, l = {l:.3f}, q = {q:g}", fontsize=8)
    ax.tick_params(labelsize=6)


def actuation_picture(data: BuildData) -> Picture | None:
    """The figure, or None without actuation."""
    block = _summary(data)
    if block is None or data.fit is None:
        return None
    sections = max(r["section"] for r in block["rows"])
    shown = min(sections, MAX_SECTIONS)
    colours = link_colours(sections)
    figure = new_figure(SIZE_IN)
    grid = figure.add_gridspec(3, shown)
    for k, q in enumerate((0.0, 1.0)):
        for i in range(shown):
            _section(figure.add_subplot(grid[k, i]), data, block, i + 1, q, colours[i])
    ax = figure.add_subplot(grid[2, :])
    for i in range(sections):
        for j in (1, 2, 3):
            rows = [r for r in block["rows"] if r["section"] == i + 1 and r["chamber"] == j]
            ax.plot([r["q"] for r in rows], [r["length_mm"] for r in rows], color=colours[i], lw=1.0,
                    ls=("-", "--", ":")[j - 1], label=f"section {i + 1}" if j == 1 else None)
    ax.set_xlabel("q")
    ax.set_ylabel("chamber length, mm (Zou et al.)")
    ax.legend(fontsize=7, ncols=min(sections, 6))
    thin = "; ".join(f"{k} {w['thickness_mm']:.3f} mm" for k, w in block["thinnest"].items())
    ext = block["extensions"]
    caption = ("Chambers (filled, numbered; 1 solid, 2 dashed, 3 dotted below) and the feeds passing each section "
               "(outlined) in the body's (N red, B green) plane at q = 0 and 1"
               + (f" (first {shown} of {sections} sections)" if shown < sections else "")
               + f". Thinnest walls: {thin}. Chamber extension (axis at q over q = 0) "
               f"{min(e['min'] for e in ext):.3f} to {max(e['max'] for e in ext):.3f}; lengths from each section's "
               f"best arc, misfit up to {max(block['arc_misfit_max_mm']):.2f} mm.")
    return picture(NAME, figure, SIZE_IN, "Actuation: chambers, feeds and their lengths", caption)
