"""How far each link of a built chain is from one constant-curvature arc at q = 1 (issue 14, item 2).

A three-chamber (or three-cable) section bends into one arc (seed 003): a link
whose q = 1 centerline is far from every arc cannot be made by one section.
Each link is fitted as :mod:`arc_design` fits a designed link (the arc from
the link's start frame F(1, l_start), least squares in closed form) on the
resampled points of the q = 1 centerline inside it and its two ends, and its
deviation is the largest true point-to-arc distance there.  Above
``ARC_TOLERANCE_MM`` the build and ``pcc design`` warn, naming the link and
the figure.  No I/O.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.geometry.blend import BlendedShape
from softdesign.geometry.frames import FramedSpline, framed_curve
from softdesign.kinematics.arc_design import DesignedLink, fit_link
from softdesign.kinematics.arc_tolerance import ARC_TOLERANCE_MM
from softdesign.kinematics.links import LinkChain

#: A resampled point this close to a link's end (in l) is that end: breaks written with six decimals (as
#: ``softdesign design`` writes them) then give the design's own samples, not the end point twice.
SNAP_L = 1e-6


def final_shape_rmf(shape: BlendedShape) -> FramedSpline:
    """The q = 1 centerline with rotation-minimizing frames: the case's own with ``frames: rmf``.

    A PCC chain's sections continue one another without twist (seed 003's D-H), which is the
    rmf transport; Frenet frames roll with the torsion, so a bending plane measured from them
    would not chain.  With ``frames: frenet`` the rmf starts from the shape's base normal.
    """
    curve = shape.curve_at(1.0)
    if curve.mode == "rmf":
        return curve
    return framed_curve(shape.smooth_curve_at(1.0), "rmf", shape.base_normal, label="q = 1 (rmf)")


def link_arcs_at_final_shape(chain: LinkChain) -> list[DesignedLink]:
    """Per link of ``chain``: its best arc at q = 1 and largest deviation (``start``, ``end`` index its samples)."""
    curve = final_shape_rmf(chain.shape)
    grid = chain.shape.smooth_curve_at(1.0).l_grid
    out = []
    for l_start, l_end in zip(chain.breaks[:-1], chain.breaks[1:], strict=True):
        inside = grid[(grid > l_start + SNAP_L) & (grid < l_end - SNAP_L)]
        l = np.concatenate([[l_start], inside, [l_end]])
        s = curve.curve.arc_length(l)
        out.append(fit_link(curve.points(l), curve.frames(l), s - s[0], 0, len(l) - 1))
    return out


def arc_misses(arcs: list[DesignedLink], tolerance_mm: float = ARC_TOLERANCE_MM) -> list[str]:
    """One sentence per link whose q = 1 centerline is more than ``tolerance_mm`` from its best arc."""
    return [
        f"link {j}: at q = 1 its centerline is up to {arc.max_deviation_mm:.3g} mm from the best constant-curvature "
        f"arc (tolerance {tolerance_mm:g} mm), so one PCC section cannot make it; use more links "
        f"(softdesign design CASE --tolerance-mm {tolerance_mm:g})"
        for j, arc in enumerate(arcs)
        if arc.max_deviation_mm > tolerance_mm
    ]


def arc_check_metrics(chain: LinkChain, tolerance_mm: float = ARC_TOLERANCE_MM) -> dict[str, Any]:
    """Manifest figures: the tolerance, every link's deviation at q = 1 (mm) and the warnings."""
    arcs = link_arcs_at_final_shape(chain)
    return {
        "q": 1.0,
        "tolerance_mm": tolerance_mm,
        "max_deviation_mm": [arc.max_deviation_mm for arc in arcs],
        "warnings": arc_misses(arcs, tolerance_mm),
    }
