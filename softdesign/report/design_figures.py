"""The design panel (issue 14, item 3): the q = 1 centerline, one constant-curvature arc per link, their error.

Left: the centerline at q = 1 (grey) in its principal view, each link's best
arc drawn from the link's own start frame (the link's colour, dashed), and the
arcs chained by seed 003's improved D-H from the base frame (black, dotted),
whose drift is the error a PCC actuator of these sections would make.  Right:
along the centerline, each sample's true distance to its link's arc, with the
stated tolerance (``arc_check.ARC_TOLERANCE_MM``).
"""

from __future__ import annotations

import numpy as np

from softdesign.kinematics import pcc
from softdesign.kinematics.arc_check import ARC_TOLERANCE_MM, SNAP_L
from softdesign.kinematics.arc_design import distances_to_arcs
from softdesign.kinematics.links import LinkChain
from softdesign.report.plotting import Picture, fixed_figure, link_colours, picture, styled
from softdesign.report.projection import principal_view
from softdesign.types import FloatArray

SIZE_IN = (12.0, 4.8)
#: Fixed layout of the two panels, inches: margins (left, right, bottom, top) and the gap between them,
#: room for tick labels up to 6 characters wide, the axis labels and one line of title.
MARGINS_IN, GAP_IN = (0.7, 0.2, 0.5, 0.3), 0.85
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
        left.legend(loc="best", fontsize=7)
        for j, (s, d) in enumerate(zip(series["along"], series["distance"], strict=True)):
            right.plot(s, d, color=colours[j], lw=1.4, label=f"link {j}: max {d.max():.3g} mm")
        right.axhline(ARC_TOLERANCE_MM, color="k", lw=0.8, ls="--", label=f"tolerance {ARC_TOLERANCE_MM:g} mm")
        right.set(xlabel="arc length at q = 1 (mm)", ylabel="distance to the link's arc (mm)",
                  title="per-link error", ylim=(0.0, None))
        right.legend(loc="best", fontsize=7)
    caption = (
        "Each link's best constant-curvature arc (seed 003's section) at q = 1, started on the link's start frame "
        "(least squares, as softdesign design fits it), over the centerline; the dotted line chains those arcs from "
        "the base frame by seed 003's improved D-H, so its drift from the centerline is what an actuator of one PCC "
        "section per link would miss. Right: each centerline sample's true distance to its link's arc. "
        "`softdesign design CASE --tolerance-mm T` chooses the fewest links within T."
    )
    return picture("design.png", figure, SIZE_IN, "Link design: one constant-curvature arc per link", caption)
