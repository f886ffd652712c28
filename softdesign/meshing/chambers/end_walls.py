"""What a tilted end cut leaves of the end walls of the chambers at the body's two ends (issue 45).

A chamber's flat end lies ``actuation.end_wall_mm`` inside its section along
the centerline (:mod:`softdesign.meshing.chambers.layout`), but the body's
end face may be cut on a slant (``fit.end_cut``: the vessel's cap plane, up to
30 degrees off the normal plane).  Where the cut plane reaches further into
the body than the end wall over a chamber's end disc, the chamber opens
through the end face: the body is then not one closed shell around closed
(or fed) chambers, and the mesh check fails (Euler characteristic 0 on the
sample case, whose base face leans 6.7 degrees, at ``end_wall_mm: 0.2``).

Assumptions: near each end the body is straight over the end wall (the
plane is carried by the end frame, the chamber's end disc is normal to the
centerline there), so the plane's depth along the axis over a point at
``r (cos a N + sin a B)`` is linear in it; with the plane's outward unit normal
``n = (n_N, n_B, n_T)`` in the end frame and its offset ``o`` along the outward
tangent, the deepest point of a disc of diameter D centred at distance d and
angle beta is ``(d (cos beta n_N + sin beta n_B) + D/2 sqrt(n_N^2 + n_B^2)) /
|n_T| - o`` inside the end: the lean the end wall must exceed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.volume import EndCuts

#: The least wall the end cut may leave over a chamber's end along the centerline, mm: where the chamber's flat end
#: and the cut face come closest the boolean's two faces must not touch.  The sample case's base leans 0.267 mm
#: over its third chamber and builds at end_wall_mm 0.28 (tests/attacks/test_mesher_bounds.py).
END_WALL_CLEARANCE_MM = 0.01


@dataclass(frozen=True)
class EndLean:
    """How deep the end cut reaches over one chamber's end disc, mm along the centerline from the end's centre."""

    end: str
    section: int
    chamber: int
    lean_mm: float


def end_leans(layout: ChamberLayout, end_cuts: EndCuts) -> list[EndLean]:
    """The cut's depth over each end chamber's disc: the base's over section 0's chambers (at their start), the
    tip's over the last section's (at their end); none at an end cut square to the centerline (``None``).

    Parameters
    ----------
    layout : the chambers (distance and diameter at their ends, angle in the body's RMF)
    end_cuts : (base, tip), each (n_N, n_B, n_T, offset_mm) in the end frame (outward normal, offset along the
        outward tangent) or None
    """
    out = []
    for end, cut, section in (("base", end_cuts[0], 0), ("tip", end_cuts[1], layout.sections - 1)):
        if cut is None:
            continue
        n_n, n_b, n_t, offset = cut
        size = math.sqrt(n_n * n_n + n_b * n_b + n_t * n_t)
        across, along = math.hypot(n_n, n_b) / size, abs(n_t) / size
        for c in layout.section_chambers(section):
            at = c.l_start if end == "base" else c.l_end
            d, big = float(c.distance_at(at)), float(c.diameter_at(at))
            reach = d * (math.cos(c.angle) * n_n + math.sin(c.angle) * n_b) / size + 0.5 * big * across
            out.append(EndLean(end, c.section, c.index, reach / along - offset))
    return out


def end_wall_problem(layout: ChamberLayout, end_cuts: EndCuts, end_wall_mm: float) -> str | None:
    """Why ``end_wall_mm`` lets a chamber break through a tilted end face (None when it does not): the deepest
    lean, where, and the end wall that works (rounded up to 0.01 mm)."""
    leans = end_leans(layout, end_cuts)
    if not leans:
        return None
    worst = max(leans, key=lambda e: e.lean_mm)
    if end_wall_mm >= worst.lean_mm + END_WALL_CLEARANCE_MM:
        return None
    works = math.ceil((worst.lean_mm + END_WALL_CLEARANCE_MM) * 100.0 - 1e-9) / 100.0
    return (f"actuation.end_wall_mm {end_wall_mm:g} is thinner than the {worst.end} face's slant reaches into the body "
            f"over chamber {worst.chamber + 1} of section {worst.section + 1} ({worst.lean_mm:.3f} mm: the end is cut "
            f"on the vessel's cap plane, fit.end_cut), so the chamber would open through the end face; use "
            f"actuation.end_wall_mm: {works:g} or more, or fit.end_cut: normal (square ends)")
