"""Binary STL bytes of a triangle mesh: what trimesh's exporter writes, without building a ``trimesh.Trimesh``.

The exporter asks a mesh object for its triangles and face normals, which it
caches under a content hash of its arrays: on the 1M-triangle benchmark's 41
meshes of 57k faces that hashing and bookkeeping was half the writes' time.
Here trimesh's normals are computed the way it computes them, on coordinate
rows (:func:`~softdesign.geometry.edges.unit_normal_rows`: the same float64
numbers, a face too small for a normal gets zeros as trimesh pads it), and
the records are packed in the same layout (an 80-byte zero header, the face
count, then per face the normal, the three corners in float32 and a zero
attribute word) straight into the file's buffer: the same bytes
(``tests/io/test_stl_bytes.py`` compares them with trimesh's export).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.geometry.edges import corner_planes, unit_normal_rows

#: One binary STL record, and the file's header.
STL_RECORD = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
STL_HEADER = np.dtype([("header", np.void, 80), ("face_count", "<u4")])
#: The float32 values of one record: its normal and its three corners.
_RECORD_FLOATS = 12


def binary_stl_bytes(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> bytes:
    """The binary STL file of the triangles ``faces`` (F, 3) int over ``vertices`` (V, 3) float, mm."""
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    count = len(faces)
    data = np.zeros(STL_HEADER.itemsize + count * STL_RECORD.itemsize, np.uint8)
    data[:STL_HEADER.itemsize].view(STL_HEADER)["face_count"] = count
    if not count:
        return data.tobytes()
    corners = corner_planes(np.asarray(vertices, np.float64), faces)  # each (3, F)
    values = np.empty((_RECORD_FLOATS, count), "<f4")  # x, y, z of the normal, then of each corner: rows
    values[0:3] = unit_normal_rows(*corners)[0]
    for k, corner in enumerate(corners):
        values[3 + 3 * k:6 + 3 * k] = corner
    records = data[STL_HEADER.itemsize:].reshape(count, STL_RECORD.itemsize)
    records[:, :4 * _RECORD_FLOATS] = values.T.copy().view(np.uint8)  # the attribute word stays zero
    return data.tobytes()
