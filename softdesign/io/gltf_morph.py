"""One glTF 2.0 binary (``morph.glb``) whose mesh morphs over q: a morph target per q and an animation.

The mesh is the surface at the first q (the base); morph target k holds the
displacement from the base to the surface at q_k (all zeros for k = 0), so with
the weights one-hot at target k a viewer shows the surface at q_k exactly.  The
animation drives the node's weights along time t = q (seconds): at t = q_k the
weights are one-hot at k, and glTF's linear interpolation between two keys
blends the surfaces at q_k and q_{k+1} linearly (the surface in between is
that blend, not S(q), which the export's q_*.* files give).  The targets' names
(``q_0.500``) are in the mesh's ``extras.targetNames``, as Blender and three.js
read them.

Coordinates are metres (glTF's unit: mm x 0.001), float32; indices are uint32.
Every POSITION accessor (base and targets) and the animation's input carry
min and max equal to their data, as the glTF specification requires.
pygltflib (MIT licence) writes the file; the bytes depend only on the arrays.
"""

from __future__ import annotations

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.formats import MM_PER_M
from softdesign.types import FloatArray, IntArray

#: glTF component types and buffer-view targets (glTF 2.0, 3.6.2).
FLOAT, UNSIGNED_INT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


def morph_glb_bytes(vertices_mm: FloatArray, faces: IntArray, q_values: FloatArray) -> bytes:
    """The .glb bytes of a mesh with one morph target per q and a linear animation over t = q.

    Parameters
    ----------
    vertices_mm : (m, V, 3) float, mm: the surface at each q, vertex k the same point of the body at every q
    faces : (F, 3) int, indices into the V vertices, shared by every q
    q_values : (m,) strictly increasing: the keyframe times (seconds)

    Raises
    ------
    InputDataError
        Arrays of the wrong shape, q not strictly increasing, or faces indexing past the vertices.
    """
    import pygltflib as gl

    vertices_mm = np.asarray(vertices_mm, float)
    faces = np.asarray(faces)
    q = np.asarray(q_values, float)
    if vertices_mm.ndim != 3 or vertices_mm.shape[2] != 3 or vertices_mm.shape[0] != len(q) or len(q) < 1:
        raise InputDataError(f"morph.glb: expected vertices (m, V, 3) for m = {len(q)} q values, "
                             f"got {vertices_mm.shape}")
    if np.any(np.diff(q) <= 0):
        raise InputDataError(f"morph.glb: the q values must increase strictly, got {q.tolist()}")
    count = vertices_mm.shape[1]
    if faces.ndim != 2 or faces.shape[1] != 3 or faces.min(initial=0) < 0 or faces.max(initial=0) >= count:
        raise InputDataError(f"morph.glb: faces must be (F, 3) indices below {count}, got {faces.shape}")
    metres = (vertices_mm / MM_PER_M).astype(np.float32)
    base = metres[0]
    blocks = [np.ascontiguousarray(faces, np.uint32).reshape(-1), base]
    blocks += [(m - base).astype(np.float32) for m in metres]
    times = q.astype(np.float32)
    weights = np.eye(len(q), dtype=np.float32)  # key k: one-hot at target k
    blocks += [times, weights.reshape(-1)]

    blob = b""
    views, accessors = [], []
    for index, block in enumerate(blocks):
        data = np.ascontiguousarray(block).tobytes()
        target = ELEMENT_ARRAY_BUFFER if index == 0 else ARRAY_BUFFER if index <= len(q) + 1 else None
        views.append(gl.BufferView(buffer=0, byteOffset=len(blob), byteLength=len(data), target=target))
        blob += data + b"\0" * (-len(data) % 4)
        if index == 0:
            accessors.append(gl.Accessor(bufferView=index, componentType=UNSIGNED_INT, count=block.size,
                                         type=gl.SCALAR, min=[int(block.min())], max=[int(block.max())]))
        elif index <= len(q) + 1:
            accessors.append(gl.Accessor(bufferView=index, componentType=FLOAT, count=len(block), type=gl.VEC3,
                                         min=[float(x) for x in block.min(axis=0)],
                                         max=[float(x) for x in block.max(axis=0)]))
        elif block is times:
            accessors.append(gl.Accessor(bufferView=index, componentType=FLOAT, count=len(times), type=gl.SCALAR,
                                         min=[float(times.min())], max=[float(times.max())]))
        else:
            accessors.append(gl.Accessor(bufferView=index, componentType=FLOAT, count=block.size, type=gl.SCALAR))
    names = [f"q_{v:.3f}" for v in q]
    primitive = gl.Primitive(attributes=gl.Attributes(POSITION=1), indices=0, mode=gl.TRIANGLES,
                             targets=[gl.Attributes(POSITION=2 + k) for k in range(len(q))])
    gltf = gl.GLTF2(
        asset=gl.Asset(version="2.0", generator="softdesign (pygltflib)"),
        scene=0,
        scenes=[gl.Scene(nodes=[0])],
        nodes=[gl.Node(mesh=0, name="actuator")],
        meshes=[gl.Mesh(name="actuator", primitives=[primitive], weights=[1.0] + [0.0] * (len(q) - 1),
                        extras={"targetNames": names})],
        animations=[gl.Animation(name="morph over q", channels=[
            gl.AnimationChannel(sampler=0, target=gl.AnimationChannelTarget(node=0, path="weights"))
        ], samplers=[gl.AnimationSampler(input=len(blocks) - 2, output=len(blocks) - 1, interpolation="LINEAR")])],
        accessors=accessors,
        bufferViews=views,
        buffers=[gl.Buffer(byteLength=len(blob))],
    )
    gltf.set_binary_blob(blob)
    return b"".join(gltf.save_to_bytes())
