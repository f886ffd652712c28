"""The mesh volume check's tolerance and the fewest vertices around it admits (pure Python: the case schema uses them).

Kept apart from :mod:`softdesign.meshing.checks` (numpy, the checks
themselves) so that loading a case file imports no numerical library.
"""

from __future__ import annotations

import math

#: Largest |mesh volume / integrated volume - 1| a kept mesh may have (issue 5).
VOLUME_RTOL = 0.005


def fewest_sides_within(rtol: float) -> int:
    """The least na whose inscribed regular na-gon misses at most ``rtol`` of its circle's area.

    The na-gon holds sin(h) / h of the circle (h = 2 pi / na, as
    :func:`~softdesign.meshing.volume.polygon_area_ratio` computes it), about
    1 - h^2 / 6, so na is near 2 pi / sqrt(6 rtol); the loop settles the exact integer.
    """
    na = 3
    while 1.0 - math.sin(2.0 * math.pi / na) / (2.0 * math.pi / na) > rtol:
        na += 1
    return na


#: Fewest vertices around a section (``export.angular_count``) the volume check can accept: 37 for
#: VOLUME_RTOL = 0.005.  The mesh's rings are polygons inscribed in the surface while the volume it is
#: checked against is integrated from the smooth surface, so even a straight round tube meshes
#: sin(h) / h of its volume (h = 2 pi / na): 36 sides lose 0.507 %, 37 lose 0.480 %.  Fewer sides
#: are bound to fail the check; a bent or elliptical section loses more than a round one and may need
#: more (the check's message says which key to raise).
MIN_ANGULAR_COUNT = fewest_sides_within(VOLUME_RTOL)

#: The largest share of a section's area the chambers and feeds of ``actuation`` may take, for the bound below.
MAX_CAVITY_SHARE = 0.4
#: Fewest vertices around a section with actuation's chambers: 47.  The cavities are meshed with the area of
#: their circles (chambers.area_radius), so the whole of the body polygon's missing area falls on the solid that
#: is left: its relative error is the polygon's divided by (1 - the cavities' share).  The demo with chambers
#: at 37 sides missed by 0.503 % (issue 45); within VOLUME_RTOL for cavities of up to MAX_CAVITY_SHARE of the
#: section the polygon may miss at most VOLUME_RTOL x (1 - MAX_CAVITY_SHARE).
MIN_ANGULAR_COUNT_WITH_CAVITIES = fewest_sides_within(VOLUME_RTOL * (1.0 - MAX_CAVITY_SHARE))
