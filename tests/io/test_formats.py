"""The mesh format registry: every format round-trips a mesh, labels kept where carried; config and registry agree."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from pydantic import ValidationError
from scipy.spatial import cKDTree

from softdesign.config import Export
from softdesign.errors import InputDataError
from softdesign.io.formats import FILE_UNITS, FORMATS, MESH_FORMATS, mesh_bytes, read_mesh, write_mesh
from softdesign.io.vtk_polydata import read_polydata, triangles_from_polydata
from softdesign.meshing.solids import build_solid
from softdesign.meshing.tessellate import Region
from softdesign.meshing.topology import signed_volume, surface_area
from softdesign.meshing.volume import BodySpec
from tests.helpers.bodies import Body, straight_line

#: STL stores float32 coordinates: ~6e-8 relative, times a few for volumes and areas summed over faces.
FLOAT32_RTOL = 1e-6
#: float32 (STL, glTF) rounds coordinates below 25 mm by at most 1e-6 mm, OBJ's text by 1e-8 mm; the
#: tube's closest vertices are 0.5 mm apart, so matching within 1e-5 mm cannot pick a wrong vertex.
ROUND_TRIP_MM = 1e-5
#: mm in one unit of each file unit (written here, not taken from the package).
MM_PER_UNIT = {"mm": 1.0, "m": 1000.0}


@pytest.fixture(scope="module")
def ported():
    """A hollow tube with a port: every region but the pose's joint step."""
    return build_solid(Body(straight_line(20.0), 3.0).sections(21, 32), BodySpec(wall_mm=0.5, port_mm=1.2))


def _read_back(path, fmt):
    """Vertices in mm and faces, read by trimesh or vtk (not the package), from the file's own unit."""
    if fmt == "vtp":
        return triangles_from_polydata(read_polydata(path))
    mesh = trimesh.load(path, force="mesh", process=False)
    return np.asarray(mesh.vertices) * MM_PER_UNIT[FILE_UNITS[fmt]], np.asarray(mesh.faces)


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


def test_glb_is_in_metres_as_gltf_requires_and_the_others_in_mm(ported, tmp_path):
    # glTF 2.0: "the units for all linear distances are meters"; STL, PLY, OBJ carry no unit (mm by convention)
    assert FILE_UNITS == {"stl": "mm", "ply": "mm", "obj": "mm", "glb": "m", "vtp": "mm", "vtk": "mm"}
    # the tube runs 20 mm along z with an outer radius of 3 mm
    expected_mm = np.ptp(ported.vertices, axis=0)
    np.testing.assert_allclose(expected_mm, [6.0, 6.0, 20.0], rtol=0, atol=0.05)
    for fmt in ("glb", "stl", "obj", "ply"):
        mesh = trimesh.load(write_mesh(tmp_path / f"body.{fmt}", ported.vertices, ported.faces), force="mesh",
                            process=False)
        scale = 1e-3 if fmt == "glb" else 1.0  # file units per mm
        np.testing.assert_allclose(mesh.extents, expected_mm * scale, rtol=FLOAT32_RTOL, atol=0, err_msg=fmt)
    vertices, _ = read_mesh(tmp_path / "body.glb")  # the package reads it back into mm
    np.testing.assert_allclose(np.ptp(vertices, axis=0), expected_mm, rtol=FLOAT32_RTOL, atol=0)


def test_ply_and_vtp_keep_the_region_of_every_face(ported, tmp_path):
    assert {name for name, f in FORMATS.items() if f.carries_regions} == {"ply", "vtp"}
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


def _oriented_triangles(faces: np.ndarray) -> set[tuple[int, int, int]]:
    """Each face as a tuple starting at its smallest index, orientation kept."""
    faces = np.asarray(faces)
    first = np.argmin(faces, axis=1)
    rolled = np.stack([np.roll(f, -k) for f, k in zip(faces, first, strict=True)])
    return set(map(tuple, rolled.tolist()))


@pytest.mark.parametrize("fmt", MESH_FORMATS)
def test_every_registered_format_round_trips_through_write_and_read(ported, tmp_path, fmt):
    vertices, faces = read_mesh(write_mesh(tmp_path / f"body.{fmt}", ported.vertices, ported.faces, ported.regions))
    assert vertices.dtype == np.float64 and faces.dtype == np.int64
    assert vertices.shape == ported.vertices.shape  # shared vertices merged again, none lost
    distance, original = cKDTree(ported.vertices).query(vertices)
    assert distance.max() <= ROUND_TRIP_MM and len(set(original.tolist())) == len(original)
    assert _oriented_triangles(original[faces]) == _oriented_triangles(ported.faces)


def test_a_legacy_vtk_surface_is_read_like_the_others(ported, tmp_path):
    import vtk

    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    writer = vtk.vtkPolyDataWriter()
    writer.SetInputData(polydata_from_triangles(ported.vertices, ported.faces))
    writer.SetFileName(str(tmp_path / "body.vtk"))
    writer.SetFileTypeToBinary()
    assert writer.Write() == 1
    vertices, faces = read_mesh(tmp_path / "body.vtk")
    distance, original = cKDTree(ported.vertices).query(vertices)
    assert distance.max() == 0.0 and _oriented_triangles(original[faces]) == _oriented_triangles(ported.faces)


def test_the_registry_names_every_format_once_with_what_it_carries():
    assert MESH_FORMATS == ("stl", "ply", "obj", "glb", "vtp")  # writable, in the order messages list them
    assert set(FORMATS) == {*MESH_FORMATS, "vtk"} and FORMATS["vtk"].encode is None  # .vtk is read only
    assert all(f.suffix == f".{name}" and f.description for name, f in FORMATS.items())
    with pytest.raises(ValueError, match="mesh format must be one of stl, ply, obj, glb, vtp, got 'vtk'"):
        mesh_bytes(np.zeros((3, 3)), np.array([[0, 1, 2]]), "vtk")


def test_reading_an_unknown_suffix_lists_the_formats(tmp_path):
    with pytest.raises(InputDataError, match=r"unknown mesh format '\.vrml'; expected one of \.stl, \.ply, .*\.vtk"):
        read_mesh(tmp_path / "body.vrml")


def test_the_case_file_accepts_exactly_the_writable_formats():
    assert Export(formats=list(MESH_FORMATS)).formats == list(MESH_FORMATS)
    schema = Export.model_json_schema()["properties"]["formats"]["items"]
    assert tuple(schema["enum"]) == MESH_FORMATS
    for name in ("vtk", "vrml", "STL"):
        with pytest.raises(ValidationError, match="Input should be 'stl', 'ply', 'obj', 'glb' or 'vtp'"):
            Export(formats=[name])
