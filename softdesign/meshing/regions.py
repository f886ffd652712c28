"""A solid's faces split by region (wall, caps, chamber, port), one open surface each.

Mould makers and CFD users assign boundary conditions or print settings per
region; an STL has no face attributes, so ``export.split_regions`` writes one
STL per region beside the solid.  The pieces tile the solid: every face is in
exactly one piece, with the solid's own vertex coordinates, so along a seam
two pieces share their vertices bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.meshing.tessellate import Region
from softdesign.meshing.topology import drop_unused_vertices, surface_area
from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class RegionPiece:
    """The faces of one region with the vertices they use (an open surface).

    Attributes
    ----------
    region : Region
    vertices : (V, 3) float, mm, a subset of the solid's vertices
    faces : (F, 3) int64, indices into ``vertices``, wound as in the solid
    """

    region: Region
    vertices: FloatArray
    faces: IntArray

    @property
    def name(self) -> str:
        """The region's file stem: ``wall``, ``base_cap``, ``tip_cap``, ``chamber``, ..."""
        return self.region.name.lower()

    def area(self) -> float:
        """Total area of the faces, mm^2."""
        return surface_area(self.vertices, self.faces)


def split_by_region(
    vertices: npt.ArrayLike, faces: npt.ArrayLike, regions: npt.ArrayLike
) -> tuple[RegionPiece, ...]:
    """One piece per region present, in :class:`Region` order.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    regions : (F,) int, a :class:`Region` value per face

    Raises
    ------
    ValueError
        ``regions`` does not hold one known Region value per face.
    """
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    regions = np.asarray(regions).reshape(-1)
    known = np.array([r.value for r in Region])
    if regions.shape != (len(faces),) or not np.isin(regions, known).all():
        raise ValueError(
            f"regions: expected one value of {known.tolist()} per face ({len(faces)} faces), "
            f"got shape {regions.shape} with values {np.unique(regions).tolist()[:8]}"
        )
    pieces = []
    for region in Region:
        chosen = faces[regions == region.value]
        if len(chosen) == 0:
            continue
        pieces.append(RegionPiece(region, *drop_unused_vertices(vertices, chosen)))
    return tuple(pieces)
