"""The sample case exported as .stl, .vtp and .glb: the ParaView time series and the one morphing morph.glb.

The .pvd files are parsed with the standard library's XML parser and every file
they name is opened with vtk; morph.glb is decoded with pygltflib and numpy
(tests/helpers/gltf_rules.py), independently of the writer.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pygltflib
import pytest
import trimesh

from softdesign.pipeline.api import build_through
from tests.helpers.gltf_rules import accessor_array, target_position, validation_errors
from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow

#: The export's own check: a mesh's volume within 0.5 % of the integral over the spline surface.
VOLUME_RTOL = 5e-3
#: The morph is tessellated on one l grid for every q, the export per q: their bounding boxes agree to the
#: chord error of rings about 0.5 mm apart on a body of a few mm radius (well under 0.1 mm).
BOUNDS_ATOL_MM = 0.1
#: .vtp keeps the vertices in float64, STL in float32: coordinates below 100 mm agree to 2^-24 x 100 mm.
STL_ATOL_MM = 1e-4


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    folder = tmp_path_factory.mktemp("series")
    text = (REPO / "configs" / "demo.yaml").read_text().replace("../data", str(REPO / "data"))
    case = folder / "demo.yaml"
    case.write_text(text.replace("formats: [stl]}", "formats: [stl, vtp, glb]}"))
    build_through(case, folder / "build")
    manifest = json.loads((folder / "build" / "manifest.json").read_text())
    return folder / "build", manifest


def pvd_entries(path):
    root = ET.parse(path).getroot()
    assert (root.tag, root.get("type")) == ("VTKFile", "Collection")
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def read_vtp(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    return vtk_to_numpy(data.GetPoints().GetData()), data


def export_q(manifest):
    return sorted({o["path"][len("meshes/q_"):-4] for o in manifest["outputs"] if o["path"].endswith(".stl")})


@pytest.mark.parametrize("series, folder, suffix", [("centerlines.pvd", "centerlines", "vtp"),
                                                     ("meshes.pvd", "meshes", "vtp")])
def test_time_series_names_every_q_in_order_and_every_file_opens(build, series, folder, suffix):
    build_dir, manifest = build
    entries = pvd_entries(build_dir / series)
    labels = export_q(manifest)
    assert [f"{t:.3f}" for t, _ in entries] == labels
    assert [f for _, f in entries] == [f"{folder}/q_{q}.{suffix}" for q in labels]
    assert series in {o["path"] for o in manifest["outputs"]}  # recorded with its sha256
    for time, file in entries:
        points, data = read_vtp(build_dir / file)
        assert len(points) > 0
        if folder == "meshes":  # the same vertices as the STL of that q (bounds: STL stores float32)
            stl = trimesh.load(build_dir / f"meshes/q_{time:.3f}.stl")
            np.testing.assert_allclose([points.min(0), points.max(0)], stl.bounds, rtol=0, atol=STL_ATOL_MM)
        else:
            assert data.GetPointData().GetArray("Stretch") is not None


def test_morph_glb_passes_the_validator_rules_and_each_target_is_the_body_at_its_q(build):
    build_dir, manifest = build
    gltf = pygltflib.GLTF2.load(str(build_dir / "morph.glb"))
    assert validation_errors(gltf) == []
    labels = export_q(manifest)
    primitive = gltf.meshes[0].primitives[0]
    assert gltf.meshes[0].extras["targetNames"] == [f"q_{q}" for q in labels]
    base = accessor_array(gltf, primitive.attributes.POSITION).astype(float)
    faces = accessor_array(gltf, primitive.indices).reshape(-1, 3)
    expected = {o["path"]: o for o in manifest["outputs"]}
    summary = json.loads((build_dir / "export" / "summary.json").read_text())["meshes"]
    for label, target in zip(labels, primitive.targets, strict=True):
        body = trimesh.Trimesh((base + accessor_array(gltf, target_position(target))) * 1000.0, faces, process=False)
        assert body.is_watertight and body.is_winding_consistent
        np.testing.assert_allclose(body.volume, summary[f"meshes/q_{label}.stl"]["volume_expected_mm3"],
                                   rtol=VOLUME_RTOL)
        stl = trimesh.load(build_dir / f"meshes/q_{label}.stl")
        np.testing.assert_allclose(body.bounds, stl.bounds, rtol=0, atol=BOUNDS_ATOL_MM)
    assert "morph.glb" in expected
    np.testing.assert_array_equal(accessor_array(gltf, gltf.animations[0].samplers[0].input)[:, 0],
                                  np.array(labels, float).astype(np.float32))
    scene = trimesh.load(build_dir / "morph.glb", force="mesh")  # another reader: the base mesh, in metres
    np.testing.assert_allclose(scene.extents * 1000.0, trimesh.load(build_dir / f"meshes/q_{labels[0]}.stl").extents,
                               rtol=0, atol=BOUNDS_ATOL_MM)
