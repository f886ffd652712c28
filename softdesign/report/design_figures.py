"""The design panel: the composed chain of a ``design:`` (issue 30), else one arc per link (issue 14, item 3).

With a design (``design/summary.json``): the chain of constant-curvature
sections composed from the base frame (each section its colour) over the q = 1
centerline, and along l each centerline sample's true distance to the chain
against the tolerance; the tip error in the title.  Without one, as below.

Left: the centerline at q = 1 (grey) in its principal view, each link's best
arc drawn from the link's own start frame (the link's colour, dashed), and the
arcs chained by seed 003's improved D-H from the base frame (black, dotted),
whose drift is the error a PCC actuator of these sections would make.  Right:
along the centerline, each sample's true distance to its link's arc, with the
stated tolerance (``arc_check.ARC_TOLERANCE_MM``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softdesign.kinematics import pcc
from softdesign.kinematics.arc_check import ARC_TOLERANCE_MM, SNAP_L
from softdesign.kinematics.arc_design import distances_to_arcs
from softdesign.kinematics.links import LinkChain
from softdesign.report.plotting import Picture, fixed_figure, link_colours, picture, styled
from softdesign.report.projection import principal_view
from softdesign.types import FloatArray

SIZE_IN = (12.0, 5.65)
#: Fixed layout of the two panels, inches: margins (left, right, bottom, top) and the gap between them,
#: room for tick labels up to 6 characters wide, the axis labels and one line of title.
MARGINS_IN, GAP_IN = (0.7, 0.2, 1.35, 0.3), 0.85
#: The legends sit below their axes' place (under the x label), in columns, so they never cover a curve (issue 34:
#: the legend placed "best" inside covered them): their top this far above the figure's bottom edge, inches.
LEGEND_TOP_IN, LEGEND_COLUMNS = MARGINS_IN[2] - 0.55, 3
#: Samples drawn along each arc.
ARC_SAMPLES = 60


def _link_samples(chain: LinkChain, j: int) -> FloatArray:
    """l of link j's samples: its ends and the resampled points inside (as arc_check fits them)."""
    grid = chain.shape.smooth_curve_at(1.0).l_grid
    l_start, l_end = chain.breaks[j], chain.breaks[j + 1]
    inside = grid[(grid > l_start + SNAP_L) & (grid < l_end - SNAP_L)]
    return np.concatenate([[l_start], inside, [l_end]])


def design_series(chain: LinkChain) -> dict[str, list]:
    """Per link: its samples' arc length (mm), their distance to its arc (mm), the arc in world mm; and the chain."""
    from softdesign.kinematics.arc_check import final_shape_rmf, link_arcs_at_final_shape

    curve = final_shape_rmf(chain.shape)
    arcs = link_arcs_at_final_shape(chain)
    along, distance, drawn = [], [], []
    for j, arc in enumerate(arcs):
        l = _link_samples(chain, j)
        start = curve.poses(l[:1])[0]
        local = (curve.points(l) - start[:3, 3]) @ start[:3, :3]
        w = arc.kappa * np.array([[np.cos(arc.phi), np.sin(arc.phi)]])
        distance.append(distances_to_arcs(local, w, np.array([arc.length]))[0])
        along.append(curve.curve.arc_length(l))
        shape = pcc.tip_position_from_arc(arc.kappa, arc.phi, np.linspace(0.0, arc.length, ARC_SAMPLES))
        drawn.append(shape @ start[:3, :3].T + start[:3, 3])
    kappa, phi, length = (np.array([getattr(a, k) for a in arcs]) for k in ("kappa", "phi", "length"))
    base = curve.poses([0.0])[0]
    chained = pcc.sample_backbone(kappa, phi, length) @ base[:3, :3].T + base[:3, 3]
    return {"along": along, "distance": distance, "arcs": drawn, "chained": [chained],
            "centerline": [curve.points(np.linspace(0.0, 1.0, 400))]}


def _legend_below(axes) -> None:
    """The legend centred under the axes' grid cell (an equal-aspect axes shrinks inside it), above the edge."""
    cell = axes.get_position(original=True)
    axes.legend(loc="upper center", bbox_to_anchor=(0.5 * (cell.x0 + cell.x1), LEGEND_TOP_IN / SIZE_IN[1]),
                bbox_transform=axes.figure.transFigure, ncol=LEGEND_COLUMNS, fontsize=7, frameon=False)


def design_picture(chain: LinkChain) -> Picture:
    """The panel's figure: arcs over the centerline, and the distance along it against the tolerance."""
    series = design_series(chain)
    colours = link_colours(chain.count)
    centerline = series["centerline"][0]
    view = principal_view(centerline, centerline[-1] - centerline[0])
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, (GAP_IN, 0.0), (1, 2))
        left, right = figure.subplots(1, 2, width_ratios=[1.3, 1.0])
        xy = view.project(centerline)
        left.plot(xy[:, 0], xy[:, 1], color="0.6", lw=3.0, label="centerline, q = 1")
        for j, arc in enumerate(series["arcs"]):
            a = view.project(arc)
            left.plot(a[:, 0], a[:, 1], color=colours[j], lw=1.4, ls="--", label=f"link {j} arc")
        chained = view.project(series["chained"][0])
        left.plot(chained[:, 0], chained[:, 1], color="k", lw=1.0, ls=":", label="arcs chained by D-H")
        left.set(aspect="equal", xlabel=view.labels[0], ylabel=view.labels[1], title="one arc per link")
        _legend_below(left)
        for j, (s, d) in enumerate(zip(series["along"], series["distance"], strict=True)):
            right.plot(s, d, color=colours[j], lw=1.4, label=f"link {j}: max {d.max():.3g} mm")
        right.axhline(ARC_TOLERANCE_MM, color="k", lw=0.8, ls="--", label=f"tolerance {ARC_TOLERANCE_MM:g} mm")
        right.set(xlabel="arc length at q = 1 (mm)", ylabel="distance to the link's arc (mm)",
                  title="per-link error", ylim=(0.0, None))
        _legend_below(right)
    caption = (
        "Each link's best constant-curvature arc (Zou et al.'s section) at q = 1, started on the link's start frame "
        "(least squares, as softdesign design fits it), over the centerline; the dotted line chains those arcs from "
        "the base frame by Zou et al.'s improved D-H, so its drift from the centerline is what an actuator of one PCC "
        "section per link would miss. Right: each centerline sample's true distance to its link's arc. "
        "`softdesign design CASE --tolerance-mm T` chooses the fewest links within T."
    )
    return picture("design.png", figure, SIZE_IN, "Link design: one constant-curvature arc per link", caption)


def panel_title(build_dir: Path) -> str:
    """The report section's title: the composed design's when the build has one."""
    from softdesign.pipeline.stages.design import load_design

    if load_design(build_dir) is None:
        return "Link design: one constant-curvature arc per link"
    return "Design: constant-curvature sections composed from the base"


def panel_picture(chain: LinkChain, build_dir: Path) -> Picture:
    """The composed design's figure when the build has a design, else :func:`design_picture`."""
    from softdesign.pipeline.stages.design import load_design

    design = load_design(build_dir)
    return design_picture(chain) if design is None else chain_picture(design.document, design.profile)


def chain_picture(document: dict[str, Any], profile: dict[str, np.ndarray]) -> Picture:
    """The composed chain over the target, and the deviation along l against the tolerance (issue 30)."""
    target, points, s = profile["target_points"], profile["chain_points"], profile["chain_s"]
    joints = np.concatenate([[0.0], np.cumsum([k["length"] for k in document["links"]])])
    colours = link_colours(len(document["links"]))
    view = principal_view(target, target[-1] - target[-2 if len(target) > 1 else 0])
    length = float(np.sum(np.linalg.norm(np.diff(target, axis=0), axis=1)))
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, (GAP_IN, 0.0), (1, 2))
        left, right = figure.subplots(1, 2, width_ratios=[1.3, 1.0])
        xy = view.project(target)
        left.plot(xy[:, 0], xy[:, 1], color="0.6", lw=3.0, label="centerline, q = 1")
        for j in range(len(document["links"])):
            inside = (s >= joints[j]) & (s <= joints[j + 1])
            a = view.project(points[inside])
            left.plot(a[:, 0], a[:, 1], color=colours[j], lw=1.4, label=f"section {j}")
        base = view.project(np.array(document["base_frame"])[None, :3, 3])
        left.plot(base[:, 0], base[:, 1], "ko", ms=4, label="base frame")
        left.set(aspect="equal", xlabel=view.labels[0], ylabel=view.labels[1], title="chain composed from the base")
        _legend_below(left)
        right.plot(profile["l"] * length, profile["deviation_mm"], color="k", lw=1.2, label="centerline to chain")
        for j, link in enumerate(document["links"]):
            right.axvspan(link["l_start"] * length, link["l_end"] * length, color=colours[j], alpha=0.12, lw=0)
        right.axhline(document["tolerance_mm"], color="k", lw=0.8, ls="--",
                      label=f"tolerance {document['tolerance_mm']:g} mm")
        right.set(xlabel="arc length of the centerline (mm)", ylabel="distance to the composed chain (mm)",
                  title=f"tip off by {document['tip_error_mm']:.3g} mm, {document['tip_error_deg']:.3g} deg",
                  ylim=(0.0, None))
        _legend_below(right)
    verdict = "within" if document["meets_tolerance"] else "NOT within"
    caption = (
        f"{len(document['links'])} constant-curvature sections (Zou et al.), section 1 on the centerline's base frame "
        "and each next one on the previous tip, over the q = 1 centerline. Right: each centerline sample's true "
        f"distance to the chain (shaded: the sections' l ranges); both ways the chain is at most "
        f"{document['chain_max_deviation_mm']:.3g} mm from the centerline, {verdict} the tolerance; the tip is "
        f"{document['tip_error_mm']:.3g} mm and {document['tip_error_deg']:.3g} deg off (design/summary.json)."
    )
    return picture("design.png", figure, SIZE_IN, "Design: constant-curvature sections composed from the base",
                   caption)
