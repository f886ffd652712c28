"""What a casting mould is asked to be (the case file's ``export.mould``), free of geometry imports.

The case file's schema checks against these numbers before any work starts;
:mod:`softdesign.meshing.mould.parts` builds the mould.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Least material between a key's socket and the cavity, or between two channels, mm.
MIN_MOULD_WALL_MM = 1.0


@dataclass(frozen=True)
class MouldSpec:
    """The case file's ``export.mould`` keys.

    Attributes
    ----------
    margin_mm : mould material around the body's bounding box on every side
    clearance_mm : how much wider and deeper a key's socket is than its bump
    key_mm : the keys' diameter
    pour_mm, vent_mm : the pour channel's and the vent's diameters
    print_mm : how far the core print reaches beyond the box
    up : casting orientation, ``base`` or ``tip`` end up
    segments : polygon sides of keys, channels and the core print's outer part
    """

    margin_mm: float = 10.0
    clearance_mm: float = 0.2
    key_mm: float = 4.0
    pour_mm: float = 4.0
    vent_mm: float = 2.0
    print_mm: float = 10.0
    up: str = "base"
    segments: int = 48
