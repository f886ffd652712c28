"""The walls around an actuated body's chambers and feeds, and each chamber's extension, at one q.

In-section measure
    Chambers and feeds are tubes whose sections are circles in the body's
    normal planes (:mod:`softdesign.meshing.chambers.carve`), and the offset axes'
    tangents are parallel to T there, so between two tubes at the same l the
    in-plane gap is a critical point of their 3D distance: on a section of a
    torus, the nearest points of two such tubes lie in one normal plane.  Two
    members at fixed (distance, angle) in the RMF therefore keep the same gap at
    every q and l: ``2 d sin(delta / 2)`` less their radii (:func:`ring_walls`).
    Against the skin, the gap changes with rho(q, l, a): at every ring of the
    member's l-range the distance from its circle to the skin's section curve,
    sampled at ``SKIN_ANGLES`` angles (:func:`skin_walls`); the skin's offset
    ``offset_mm`` is added (an offset moves the surface that far along its
    normal, which is in-plane but for the slope rho_s).
Extension
    A chamber's length is its axis's, ``integral (1 - d (k1 cos beta + k2 sin
    beta)) ds`` over its l-range (:func:`~softdesign.meshing.chambers.carve.axis_lengths`);
    its extension is that at q over that at q = 0.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.chambers.carve import piecewise_axis_length
from softdesign.meshing.chambers.layout import ChamberLayout, analytic_walls
from softdesign.meshing.volume import angle_grid
from softdesign.types import FloatArray

#: Angles at which the skin's section curve is sampled for the chamber-skin gap (1 degree apart: on a 4 mm
#: radius the vertex spacing is 0.07 mm, so over a 0.5 mm wall the nearest vertex is within 0.002 mm of the
#: nearest curve point, errs high by no more).
SKIN_ANGLES = 360
#: Rings per mm of a member's l-range for the skin gap.
RINGS_PER_MM = 2.0


@dataclass(frozen=True)
class Wall:
    """A thinnest wall: its kind, thickness (mm), and where (section and chamber 1-based, q, l, angle deg).

    A feed's wall names the chamber the feed leads to; a wall between tubes (the same in every chamber of its
    section, at every q and l) has chamber 0 and no q, l or angle.
    """

    kind: str
    thickness_mm: float
    section: int
    chamber: int
    q: float | None
    l: float | None
    angle_deg: float | None

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return asdict(self)

    def place(self) -> str:
        """``section 2 chamber 1 q=0.500 l=0.3120 angle 95 deg`` (parts that are None left out)."""
        if self.chamber == 0:  # a ring wall: the same for every chamber of the section, at every q and l
            return f"section {self.section} (every chamber, q and l)"
        feed = ("feed of " if self.kind.startswith("feed") else "channel into " if self.kind.startswith("channel")
                else "")
        parts = [f"{feed}section {self.section} chamber {self.chamber}"]
        if self.q is not None:
            parts.append(f"q={self.q:.3f}")
        if self.l is not None:
            parts.append(f"l={self.l:.4f}")
        if self.angle_deg is not None:
            parts.append(f"angle {self.angle_deg:.0f} deg")
        return " ".join(parts)


def ring_walls(layout: ChamberLayout) -> list[Wall]:
    """Per section, the chamber-chamber, chamber-feed and feed-feed gaps (the same at every q and l)."""
    out = []
    for i in range(layout.sections):
        walls = analytic_walls(layout.spec, layout.sections, i, radius_mm=np.inf)
        for kind, value in (("chamber-chamber", walls.chamber_chamber), ("chamber-feed", walls.chamber_feed),
                            ("feed-feed", walls.feed_feed)):
            if np.isfinite(value):
                out.append(Wall(kind, float(value), i + 1, 0, None, None, None))
    return out


def _members(layout: ChamberLayout) -> list[tuple[str, int, int, float, float, float, float, float]]:
    """(kind, section, chamber, distance, angle, radius, l_start, l_end) of every chamber and feed."""
    out = [("chamber-skin", c.section, c.index, c.distance_mm, c.angle, 0.5 * c.diameter_mm, c.l_start, c.l_end)
           for c in layout.chambers]
    starts = {(c.section, c.index): c.l_start for c in layout.chambers}
    out += [("feed-skin", f.section, f.chamber, f.ring_mm, f.angle, 0.5 * f.diameter_mm, 0.0,
             starts[f.section, f.chamber]) for f in layout.feeds]
    return out


def skin_walls(curve: FramedSpline, field: RadiusField, q: float, layout: ChamberLayout,
               offset_mm: float = 0.0) -> list[Wall]:
    """The thinnest skin over every chamber, feed and series channel at q, each with its l and the skin's angle.

    The radius field is evaluated once on rings ``1 / RINGS_PER_MM`` mm apart (every member's ends added);
    the gap from a circle centred at c to the skin point rho u is ``sqrt(rho^2 - 2 rho u.c + |c|^2) - r``.
    """
    a = angle_grid(SKIN_ANGLES)
    members = _members(layout)
    rings = max(3, int(np.ceil(RINGS_PER_MM * curve.length)) + 1)
    ends = [v for m in members for v in m[6:8]] + [p[0] for c in layout.channels for p in c.course]
    l = np.unique(np.concatenate([np.linspace(0.0, 1.0, rings), ends]))
    rho = field.evaluate_grid(q, l, a) + offset_mm
    out = []
    tapered = {(c.section, c.index): c for c in layout.chambers if c.profile}
    for kind, section, chamber, distance, angle, radius, l_start, l_end in members:
        rows = np.flatnonzero((l >= l_start) & (l <= l_end))
        member = tapered.get((section, chamber)) if kind == "chamber-skin" else None
        d = np.full(len(rows), distance) if member is None else member.distance_at(l[rows])
        r = np.full(len(rows), radius) if member is None else 0.5 * member.diameter_at(l[rows])
        out.append(_thinnest(kind, section, chamber, q, l, rows, a, rho, d, np.full(len(rows), angle), r))
    for channel in layout.channels:  # its course: the ring and angle change along it
        rows = np.flatnonzero((l >= channel.l_start) & (l <= channel.l_end))
        out.append(_thinnest("channel-skin", channel.section, 0, q, l, rows, a, rho, channel.ring_at(l[rows]),
                             channel.angle_at(l[rows]), np.full(len(rows), 0.5 * channel.diameter_mm)))
    return out


def _thinnest(kind: str, section: int, chamber: int, q: float, l: FloatArray, rows: np.ndarray, a: FloatArray,
              rho: FloatArray, d: FloatArray, angle: FloatArray, r: FloatArray) -> Wall:
    """The thinnest gap from circles (centre ``d`` (cos, sin) ``angle``, radius ``r`` at each ring ``rows``) to
    the skin ``rho`` (rings, angles ``a``)."""
    along = d[:, None] * np.cos(a[None, :] - angle[:, None])  # u . c
    gap = np.sqrt(np.maximum(rho[rows] ** 2 - 2.0 * rho[rows] * along + (d * d)[:, None], 0.0)) - r[:, None]
    i, k = np.unravel_index(int(np.argmin(gap)), gap.shape)
    return Wall(kind, float(gap[i, k]), section + 1, chamber + 1, float(q), float(l[rows[i]]),
                float(np.rad2deg(a[k])))


def chamber_lengths_mm(curve: FramedSpline, layout: ChamberLayout) -> FloatArray:
    """(n_sections, 3) mm: each chamber's axis length on ``curve`` (the body at some q)."""
    lengths = np.empty((layout.sections, layout.spec.chambers_per_section))
    for c in layout.chambers:
        lengths[c.section, c.index] = piecewise_axis_length(curve, layout.breaks, c.l_start, c.l_end,
                                                            c.distance_mm, c.angle)
    return lengths
