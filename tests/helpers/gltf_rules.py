"""The Khronos glTF validator's rules a test can apply to a .glb, decoded with pygltflib and numpy.

Each accessor is decoded from its buffer view by hand (component type, type,
count, offsets), independently of the writer.  :func:`validation_errors` lists
the broken rules (empty when the file passes); :func:`accessor_array` gives an
accessor's data for comparisons.  pygltflib reads an absent ``min``/``max`` as
an empty list: both mean "no bound" here.
"""

from __future__ import annotations

import numpy as np

#: glTF 2.0 component types -> numpy dtypes, and element types -> component counts.
DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def accessor_array(gltf, index: int) -> np.ndarray:
    """Accessor ``index`` as a (count, components) array (its buffer view's bytes, tightly packed)."""
    accessor = gltf.accessors[index]
    view = gltf.bufferViews[accessor.bufferView]
    dtype = np.dtype(DTYPES[accessor.componentType]).newbyteorder("<")
    width = COMPONENTS[accessor.type]
    start = (view.byteOffset or 0) + (accessor.byteOffset or 0)
    data = np.frombuffer(gltf.binary_blob(), dtype, accessor.count * width, start)
    return data.reshape(accessor.count, width)


def target_position(target) -> int:
    """A morph target's POSITION accessor (pygltflib reads targets back as plain dicts)."""
    return int(target["POSITION"] if isinstance(target, dict) else target.POSITION)


def validation_errors(gltf) -> list[str]:
    """The rules of the glTF 2.0 specification (as the Khronos validator checks them) this file breaks."""
    errors: list[str] = []
    blob = gltf.binary_blob() or b""
    if gltf.asset.version != "2.0":
        errors.append(f"asset.version {gltf.asset.version}")
    if len(gltf.buffers) != 1 or gltf.buffers[0].byteLength > len(blob) or len(blob) - gltf.buffers[0].byteLength > 3:
        errors.append("BUFFER_BYTE_LENGTH_MISMATCH")
    for i, view in enumerate(gltf.bufferViews):
        if (view.byteOffset or 0) + view.byteLength > gltf.buffers[view.buffer].byteLength:
            errors.append(f"bufferViews[{i}]: BUFFER_VIEW_TOO_LONG")
    for i, accessor in enumerate(gltf.accessors):
        view = gltf.bufferViews[accessor.bufferView]
        size = np.dtype(DTYPES[accessor.componentType]).itemsize
        offset = (view.byteOffset or 0) + (accessor.byteOffset or 0)
        if offset % size:
            errors.append(f"accessors[{i}]: ACCESSOR_TOTAL_OFFSET_ALIGNMENT")
        if (accessor.byteOffset or 0) + accessor.count * COMPONENTS[accessor.type] * size > view.byteLength:
            errors.append(f"accessors[{i}]: ACCESSOR_TOO_LONG")
            continue
        data = accessor_array(gltf, i)
        if accessor.min and not np.array_equal(np.asarray(accessor.min, data.dtype), data.min(axis=0)):
            errors.append(f"accessors[{i}]: ACCESSOR_MIN_MISMATCH")
        if accessor.max and not np.array_equal(np.asarray(accessor.max, data.dtype), data.max(axis=0)):
            errors.append(f"accessors[{i}]: ACCESSOR_MAX_MISMATCH")
        if data.dtype.kind == "f" and not np.all(np.isfinite(data)):
            errors.append(f"accessors[{i}]: ACCESSOR_INVALID_FLOAT")
    for m, mesh in enumerate(gltf.meshes):
        counts = {len(p.targets or []) for p in mesh.primitives}
        if len(counts) != 1:
            errors.append(f"meshes[{m}]: MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT")
        if mesh.weights and counts != {len(mesh.weights)}:
            errors.append(f"meshes[{m}]: MESH_INVALID_WEIGHTS_COUNT")
        for p, primitive in enumerate(mesh.primitives):
            position = gltf.accessors[primitive.attributes.POSITION]
            if not position.min or not position.max:
                errors.append(f"meshes[{m}].primitives[{p}]: MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS")
            if primitive.indices is not None and accessor_array(gltf, primitive.indices).max() >= position.count:
                errors.append(f"meshes[{m}].primitives[{p}]: ACCESSOR_INDEX_OOB")
            if primitive.indices is not None and gltf.accessors[primitive.indices].count % 3:
                errors.append(f"meshes[{m}].primitives[{p}]: MESH_PRIMITIVE_INCOMPATIBLE_MODE")
            for t, target in enumerate(primitive.targets or []):
                accessor = gltf.accessors[target_position(target)]
                if accessor.count != position.count:
                    errors.append(f"meshes[{m}].primitives[{p}].targets[{t}]: MESH_PRIMITIVE_MORPH_TARGET_INVALID_"
                                  "ATTRIBUTE_COUNT")
                if not accessor.min or not accessor.max:
                    errors.append(f"meshes[{m}].primitives[{p}].targets[{t}]: POSITION without bounds")
    for a, animation in enumerate(gltf.animations):
        for s, sampler in enumerate(animation.samplers):
            times = accessor_array(gltf, sampler.input)[:, 0]
            timing = gltf.accessors[sampler.input]
            if not timing.min or not timing.max:
                errors.append(f"animations[{a}].samplers[{s}]: ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS")
            if np.any(np.diff(times) <= 0) or times.min(initial=0.0) < 0:
                errors.append(f"animations[{a}].samplers[{s}]: ANIMATION_SAMPLER_INPUT_ACCESSOR_NON_INCREASING")
        for c, channel in enumerate(animation.channels):
            sampler = animation.samplers[channel.sampler]
            keys = gltf.accessors[sampler.input].count
            if channel.target.path == "weights":
                mesh = gltf.meshes[gltf.nodes[channel.target.node].mesh]
                targets = len(mesh.primitives[0].targets or [])
                if targets == 0 or gltf.accessors[sampler.output].count != keys * targets:
                    errors.append(f"animations[{a}].channels[{c}]: ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_COUNT")
    return errors
