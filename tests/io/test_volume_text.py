"""The volume mesh's text files at C speed: .msh the same bytes as meshio's own Gmsh 2.2 ASCII writer, .vtu read
back by meshio with every array exact, both files inline text as SOFA's loaders need."""

from __future__ import annotations

import contextlib
import io

import meshio
import numpy as np

from softdesign.io.volume_formats import NamedSets, read_volume_mesh, volume_mesh_bytes
from tests.io.test_volume_formats import cube


def named_cube() -> tuple[np.ndarray, np.ndarray, NamedSets]:
    """The cube with two named surfaces (its boundary split by the first node), a node set and a figure."""
    from softdesign.meshing.volume_mesh.tet_quality import boundary_faces

    points, tets = cube()
    points = points + np.array([1e-7, np.pi, -2.0 / 3.0])  # digits a short format would lose
    faces = boundary_faces(tets)
    low = np.any(faces == 0, axis=1)
    sets = NamedSets({"skin": faces[~low], "base": faces[low]}, {"base_nodes": np.array([0, 1, 2, 3])},
                     {"stretch_max": np.linspace(1.0, 1.5, len(tets)) + 1e-13})
    return points, tets, sets


def meshio_msh(points: np.ndarray, tets: np.ndarray, sets: NamedSets, path) -> bytes:
    """What meshio's gmsh22 ASCII writer makes of the same cells and physical groups."""
    names = list(sets.surfaces)
    cells = [("tetra", tets)] + [("triangle", sets.surfaces[n]) for n in names] + [
        ("vertex", np.asarray(v).reshape(-1, 1)) for v in sets.node_sets.values()]
    tags = list(range(1, len(cells) + 1))
    blocks = [np.full(len(c[1]), t) for c, t in zip(cells, tags, strict=True)]
    dims = [3] + [2] * len(names) + [0] * len(sets.node_sets)
    field = {n: np.array([t, d]) for n, t, d in zip(["body", *names, *sets.node_sets], tags, dims, strict=True)}
    mesh = meshio.Mesh(points, cells, cell_data={"gmsh:physical": blocks, "gmsh:geometrical": blocks},
                       field_data=field)
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    return path.read_bytes()


def test_msh_is_meshios_own_bytes(tmp_path):
    points, tets, sets = named_cube()
    ours = volume_mesh_bytes(points, tets, "msh", sets)
    assert ours == meshio_msh(points, tets, sets, tmp_path / "meshio.msh")
    plain = volume_mesh_bytes(points, tets, "msh")
    with contextlib.redirect_stderr(io.StringIO()):  # meshio warns of the missing tags it fills with zeros
        reference = tmp_path / "plain.msh"
        meshio.write(reference, meshio.Mesh(points, [("tetra", tets)], cell_data={
            "gmsh:physical": [np.ones(len(tets), int)], "gmsh:geometrical": [np.ones(len(tets), int)]}),
            file_format="gmsh22", binary=False)
    assert plain == reference.read_bytes()


def test_vtu_reads_back_exactly_with_its_arrays(tmp_path):
    points, tets, sets = named_cube()
    data = volume_mesh_bytes(points, tets, "vtu", sets)
    text = data.decode("ascii")
    assert 'format="ascii"' in text and 'format="binary"' not in text and "<AppendedData" not in text
    path = tmp_path / "cube.vtu"
    path.write_bytes(data)
    got_points, got_tets = read_volume_mesh(path)
    np.testing.assert_array_equal(got_points, points)  # 17 digits: the same doubles
    np.testing.assert_array_equal(got_tets, tets)
    mesh = meshio.read(path)
    triangles = mesh.cells_dict["triangle"]
    np.testing.assert_array_equal(triangles, np.concatenate([sets.surfaces["skin"], sets.surfaces["base"]]))
    surface = mesh.cell_data_dict["surface"]
    np.testing.assert_array_equal(surface["tetra"], -1)
    np.testing.assert_array_equal(surface["triangle"], [0] * len(sets.surfaces["skin"]) + [1] * len(
        sets.surfaces["base"]))
    np.testing.assert_array_equal(mesh.cell_data_dict["stretch_max"]["tetra"], sets.tet_data["stretch_max"])
    assert np.isnan(mesh.cell_data_dict["stretch_max"]["triangle"]).all()
    np.testing.assert_array_equal(np.flatnonzero(mesh.point_data["base_nodes"]), [0, 1, 2, 3])
    assert volume_mesh_bytes(points, tets, "vtu", sets) == data


def test_msh_element_memo_changes_no_byte_and_keys_on_the_connectivity():
    points, tets, sets = named_cube()
    memo: dict[str, str] = {}
    first = volume_mesh_bytes(points, tets, "msh", sets, memo)
    assert first == volume_mesh_bytes(points, tets, "msh", sets) and len(memo) == 1
    moved = points * 2.0  # another q: the same elements, other nodes
    assert volume_mesh_bytes(moved, tets, "msh", sets, memo) == volume_mesh_bytes(moved, tets, "msh", sets)
    assert len(memo) == 1
    flipped = tets[:, [0, 2, 1, 3]]  # another connectivity: formatted anew, not the memo's text
    assert volume_mesh_bytes(points, flipped, "msh", sets, memo) == volume_mesh_bytes(points, flipped, "msh", sets)
    assert len(memo) == 2
