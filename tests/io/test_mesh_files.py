"""Mesh files in every export format: read back with their own libraries, same solid, region labels kept."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from softdesign.io.mesh_files import LABELLED_FORMATS, MESH_FORMATS, mesh_bytes, write_mesh
from softdesign.io.vtk_polydata import read_polydata, triangles_from_polydata
from softdesign.meshing.solids import build_solid
from softdesign.meshing.tessellate import Region
from softdesign.meshing.topology import signed_volume, surface_area
from softdesign.meshing.volume import BodySpec
from tests.helpers.bodies import Body, straight_line

#: STL stores float32 coordinates: ~6e-8 relative, times a few for volumes and areas summed over faces.
FLOAT32_RTOL = 1e-6


@pytest.fixture(scope="module")
def ported():
    """A hollow tube with a port: every region but the pose's joint step."""
    return build_solid(Body(straight_line(20.0), 3.0).sections(21, 32), BodySpec(wall_mm=0.5, port_mm=1.2))


def _read_back(path, fmt):
    if fmt == "vtp":
        return triangles_from_polydata(read_polydata(path))
    mesh = trimesh.load(path, force="mesh", process=False)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


@pytest.mark.parametrize("fmt", MESH_FORMATS)
def test_every_format_reads_back_as_the_same_solid(ported, tmp_path, fmt):
    path = write_mesh(tmp_path / f"body.{fmt}", ported.vertices, ported.faces, ported.regions)
    vertices, faces = _read_back(path, fmt)
    assert len(faces) == len(ported.faces)
    for measure in (signed_volume, surface_area):
        expected = measure(ported.vertices, ported.faces)
        assert measure(vertices, faces) == pytest.approx(expected, rel=FLOAT32_RTOL), measure.__name__
    # the same arrays give the same bytes
    assert path.read_bytes() == mesh_bytes(ported.vertices, ported.faces, fmt, ported.regions)


def test_ply_and_vtp_keep_the_region_of_every_face(ported, tmp_path):
    assert set(LABELLED_FORMATS) == {"ply", "vtp"}
    assert {Region.WALL, Region.CHAMBER, Region.PORT} <= set(ported.regions.tolist())
    ply = trimesh.load(write_mesh(tmp_path / "body.ply", ported.vertices, ported.faces, ported.regions),
                       process=False)
    # the face element's "region" property, as trimesh parses it (it keeps unknown properties raw)
    np.testing.assert_array_equal(ply.metadata["_ply_raw"]["face"]["data"]["region"], ported.regions)
    poly = read_polydata(write_mesh(tmp_path / "body.vtp", ported.vertices, ported.faces, ported.regions))
    from vtk.util.numpy_support import vtk_to_numpy

    np.testing.assert_array_equal(vtk_to_numpy(poly.GetCellData().GetArray("Region")), ported.regions)
    names = poly.GetFieldData().GetAbstractArray("RegionNames")
    assert [names.GetValue(i) for i in range(names.GetNumberOfValues())] == [r.name.lower() for r in Region]


def test_an_unknown_format_is_refused():
    with pytest.raises(ValueError, match="mesh format must be one of stl, ply, obj, glb, vtp, got 'vrml'"):
        mesh_bytes(np.zeros((3, 3)), np.array([[0, 1, 2]]), "vrml")
