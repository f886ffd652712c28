"""One open surface per face region: known areas of a straight tube and a ported hollow one, tiling, errors."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.regions import split_by_region
from softdesign.meshing.solids import build_solid
from softdesign.meshing.volume import BodySpec
from softdesign.types import POINT_TOL_MM
from tests.helpers.bodies import Body, straight_line
from tests.meshing.test_meshing_solids import ROUNDOFF_RTOL, polygon_area, polygon_perimeter


def _faces_as_points(vertices, faces) -> set[tuple]:
    """Each face as its three corner coordinates (rounded for set equality), a face's identity across meshes."""
    corners = np.round(np.asarray(vertices)[np.asarray(faces)] / POINT_TOL_MM).astype(np.int64)
    return {tuple(c.ravel()) for c in corners}


def test_a_straight_tube_splits_into_its_prism_wall_and_two_polygon_caps():
    r, length, na = 3.0, 40.0, 64
    solid = build_solid(Body(straight_line(length), r).sections(41, na))
    pieces = {p.name: p for p in split_by_region(solid.vertices, solid.faces, solid.regions)}
    assert list(pieces) == ["wall", "base_cap", "tip_cap"]
    np.testing.assert_allclose(pieces["wall"].area(), polygon_perimeter(r, na) * length, rtol=ROUNDOFF_RTOL)
    for cap in ("base_cap", "tip_cap"):
        np.testing.assert_allclose(pieces[cap].area(), polygon_area(r, na), rtol=ROUNDOFF_RTOL)
        # a cap holds only its own ring: na vertices (+ a centre when fanned)
        assert len(pieces[cap].vertices) in (na, na + 1)


def test_pieces_tile_the_solid_face_for_face_with_its_own_coordinates():
    spec = BodySpec(wall_mm=0.5, port_mm=1.2, port_segments=24)
    solid = build_solid(Body(straight_line(40.0), 3.0).sections(41, 64), spec)
    pieces = split_by_region(solid.vertices, solid.faces, solid.regions)
    names = [p.name for p in pieces]
    assert {"wall", "base_cap", "tip_cap", "chamber", "chamber_cap", "port"} <= set(names)
    assert sum(len(p.faces) for p in pieces) == len(solid.faces)
    tiled = set().union(*(_faces_as_points(p.vertices, p.faces) for p in pieces))
    assert tiled == _faces_as_points(solid.vertices, solid.faces)
    for piece in pieces:
        # every vertex of a piece is one of the solid's, bit for bit, and every one is used
        assert np.isin(piece.vertices.view([("", float)] * 3), solid.vertices.view([("", float)] * 3)).all()
        assert np.array_equal(np.unique(piece.faces), np.arange(len(piece.vertices)))


def test_labels_that_are_not_regions_are_refused():
    solid = build_solid(Body(straight_line(10.0), 2.0).sections(11, 16))
    with pytest.raises(ValueError, match="one value of .* per face"):
        split_by_region(solid.vertices, solid.faces, np.full(len(solid.faces), 42))
    with pytest.raises(ValueError, match="per face"):
        split_by_region(solid.vertices, solid.faces, solid.regions[:-1])
