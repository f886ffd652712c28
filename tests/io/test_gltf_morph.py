"""morph.glb (a morph target per q, an animation over q) and the .pvd time series, on analytic shapes."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pygltflib
import pytest
import trimesh

from softdesign.errors import InputDataError
from softdesign.io.gltf_morph import morph_glb_bytes
from softdesign.io.pvd import pvd_bytes
from tests.helpers.gltf_rules import accessor_array, target_position, validation_errors

Q = np.array([0.0, 0.25, 1.0])
#: Sphere radius (mm) at each q: the morph of a sphere that grows.
RADII_MM = np.array([10.0, 12.5, 20.0])
#: float32 metres: a relative rounding of 2^-24 on coordinates below 0.02 m, then x 1000 back to mm.
FLOAT32_ATOL_MM = 20.0 * 2.0**-23


def sphere_morph():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    vertices = np.stack([sphere.vertices * r for r in RADII_MM])
    return vertices, np.asarray(sphere.faces), morph_glb_bytes(vertices, sphere.faces, Q)


def test_a_growing_sphere_reads_back_at_every_q_and_passes_the_validator_rules():
    vertices, faces, data = sphere_morph()
    gltf = pygltflib.GLTF2.load_from_bytes(data)
    assert validation_errors(gltf) == []
    primitive = gltf.meshes[0].primitives[0]
    base = accessor_array(gltf, primitive.attributes.POSITION)
    assert len(primitive.targets) == len(Q)
    assert gltf.meshes[0].extras["targetNames"] == ["q_0.000", "q_0.250", "q_1.000"]
    for k, target in enumerate(primitive.targets):  # weights one-hot at k: the surface at q_k, metres -> mm
        shown = (base.astype(float) + accessor_array(gltf, target_position(target))) * 1000.0
        np.testing.assert_allclose(shown, vertices[k], rtol=0, atol=FLOAT32_ATOL_MM)
    np.testing.assert_array_equal(accessor_array(gltf, primitive.indices).reshape(-1, 3), faces)
    sampler = gltf.animations[0].samplers[0]
    np.testing.assert_array_equal(accessor_array(gltf, sampler.input)[:, 0], Q.astype(np.float32))
    np.testing.assert_array_equal(accessor_array(gltf, sampler.output).reshape(len(Q), len(Q)), np.eye(len(Q)))
    channel = gltf.animations[0].channels[0]
    assert (channel.target.path, channel.target.node, sampler.interpolation) == ("weights", 0, "LINEAR")


def test_trimesh_reads_the_base_mesh_in_metres_and_the_bytes_repeat():
    _, _, data = sphere_morph()
    mesh = trimesh.load(trimesh.util.wrap_as_stream(data), file_type="glb", force="mesh")
    np.testing.assert_allclose(mesh.extents, 2 * RADII_MM[0] / 1000.0, rtol=1e-3)  # icosphere: vertices on r
    assert sphere_morph()[2] == data


def test_the_rules_catch_a_wrong_bound_and_a_target_count_mismatch():
    _, _, data = sphere_morph()
    gltf = pygltflib.GLTF2.load_from_bytes(data)
    gltf.accessors[1].max = [1.0, 1.0, 1.0]
    gltf.meshes[0].weights = [1.0]
    assert validation_errors(gltf) == ["accessors[1]: ACCESSOR_MAX_MISMATCH", "meshes[0]: MESH_INVALID_WEIGHTS_COUNT"]


@pytest.mark.parametrize("q, message", [([0.0, 1.0, 0.5], "increase strictly"), ([0.0, 1.0], "expected vertices")])
def test_bad_input_is_refused_with_a_message(q, message):
    vertices, faces, _ = sphere_morph()
    with pytest.raises(InputDataError, match=message):
        morph_glb_bytes(vertices, faces, q)


def test_pvd_lists_every_file_with_its_time():
    entries = [(0.0, "centerlines/q_0.000.vtp"), (1 / 3, "centerlines/q_0.333.vtp")]
    root = ET.fromstring(pvd_bytes(entries))
    assert (root.tag, root.get("type")) == ("VTKFile", "Collection")
    assert [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")] == entries
