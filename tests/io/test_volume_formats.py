"""Tetrahedral meshes written as ASCII .vtu (inline data) and Gmsh 2.2 .msh, read back by meshio."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from softdesign.errors import InputDataError
from softdesign.io.volume_formats import read_volume_mesh, volume_mesh_bytes

#: The .vtu writes 12 significant digits ("{:.11e}"): relative to a coordinate's magnitude.
VTU_RTOL = 1e-11


def cube() -> tuple[np.ndarray, np.ndarray]:
    """A 10 mm cube, offset from the origin, as six positive tetrahedra around its diagonal."""
    corners = 5.0 + 10.0 * np.array(list(itertools.product((0.0, 1.0), repeat=3))) + 1 / 3
    tets = []
    for order in itertools.permutations(range(3)):
        path = [0]
        for axis in order:
            path.append(path[-1] + (4, 2, 1)[axis])
        a, b, c = (corners[path[k]] - corners[path[0]] for k in (1, 2, 3))
        tets.append(path if np.dot(a, np.cross(b, c)) > 0 else [path[0], path[2], path[1], path[3]])
    return corners, np.array(tets, np.int64)


@pytest.mark.parametrize("suffix", ["vtu", "msh"])
def test_written_files_read_back(tmp_path, suffix):
    points, tets = cube()
    data = volume_mesh_bytes(points, tets, suffix)
    path = tmp_path / f"cube.{suffix}"
    path.write_bytes(data)
    got_points, got_tets = read_volume_mesh(path)
    np.testing.assert_array_equal(got_tets, tets)
    np.testing.assert_allclose(got_points, points, rtol=VTU_RTOL, atol=0)
    # the same arrays give the same bytes
    assert volume_mesh_bytes(points, tets, suffix) == data


def test_vtu_is_ascii_xml_with_inline_data_only():
    text = volume_mesh_bytes(*cube(), "vtu").decode("ascii")
    assert text.startswith("<?xml") and 'type="UnstructuredGrid"' in text
    assert 'format="ascii"' in text
    for other in ('format="binary"', 'format="appended"', "<AppendedData", 'encoding="raw"'):
        assert other not in text


def test_msh_is_gmsh_22_ascii_with_tetrahedra():
    lines = volume_mesh_bytes(*cube(), "msh").decode("ascii").splitlines()
    assert lines[:3] == ["$MeshFormat", "2.2 0 8", "$EndMeshFormat"]
    elements = lines[lines.index("$Elements") + 2:lines.index("$EndElements")]
    # element type 4 is the 4-node tetrahedron; two tags (physical 1, elementary 1), nodes 1-based
    assert len(elements) == 6 and all(e.split()[1:4] == ["4", "2", "1"] for e in elements)


def test_unknown_suffix_and_empty_files_are_refused(tmp_path):
    with pytest.raises(ValueError, match="one of vtu, msh"):
        volume_mesh_bytes(*cube(), "vtk")
    bad = tmp_path / "bad.vtu"
    bad.write_text("not xml")
    with pytest.raises(InputDataError, match="cannot read it as a volume mesh"):
        read_volume_mesh(bad)
    with pytest.raises(InputDataError, match="unknown volume mesh format"):
        read_volume_mesh(tmp_path / "mesh.stl")


def test_vtu_names_its_surface_codes_for_meshio(tmp_path):
    import meshio

    from softdesign.io.volume_formats import NamedSets

    points, tets = cube()
    # two named surfaces of the cube: the face z = low (two triangles) and the face z = high (two triangles)
    low = np.flatnonzero(np.isclose(points[:, 2], points[:, 2].min()))
    high = np.flatnonzero(np.isclose(points[:, 2], points[:, 2].max()))
    surfaces = {"base": np.array([low[[0, 1, 3]], low[[0, 3, 2]]]), "tip": np.array([high[[0, 1, 3]],
                                                                                      high[[0, 3, 2]]])}
    path = tmp_path / "named.vtu"
    path.write_bytes(volume_mesh_bytes(points, tets, "vtu", NamedSets(surfaces=surfaces)))
    mesh = meshio.read(path)
    # meshio's own form for a Gmsh file's physical names: name -> [code, dimension]
    assert {name: value.tolist() for name, value in mesh.field_data.items()} == {
        "body": [-1, 3], "base": [0, 2], "tip": [1, 2]}
    codes = mesh.cell_data_dict["surface"]
    np.testing.assert_array_equal(codes["tetra"], np.full(len(tets), -1))
    for name, triangles in surfaces.items():  # the cells a name's code selects are that surface's triangles
        chosen = codes["triangle"] == mesh.field_data[name][0]
        np.testing.assert_array_equal(mesh.cells_dict["triangle"][chosen], triangles)
    # without named surfaces there are no codes to name
    plain = tmp_path / "plain.vtu"
    plain.write_bytes(volume_mesh_bytes(points, tets, "vtu"))
    assert meshio.read(plain).field_data == {}
