"""Binary STL bytes of a triangle mesh: what trimesh's exporter writes, without building a ``trimesh.Trimesh``.

The exporter asks a mesh object for its triangles and face normals, which it
caches under a content hash of its arrays: on the 1M-triangle benchmark's 41
meshes of 57k faces that hashing and bookkeeping was half the writes' time.
Here the same trimesh functions (``triangles.cross`` and ``triangles.normals``)
compute the normals from the same float64 corners, a face too small for a
normal gets zeros as trimesh pads it, and the records are packed in the same
layout (an 80-byte zero header, the face count, then per face the normal, the
three corners in float32 and a zero attribute word): the same bytes
(``tests/io/test_stl_bytes.py`` compares them with trimesh's export).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: One binary STL record, and the file's header.
STL_RECORD = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
STL_HEADER = np.dtype([("header", np.void, 80), ("face_count", "<u4")])


def binary_stl_bytes(vertices: npt.ArrayLike, faces: npt.ArrayLike) -> bytes:
    """The binary STL file of the triangles ``faces`` (F, 3) int over ``vertices`` (V, 3) float, mm."""
    from trimesh import triangles

    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    header = np.zeros(1, dtype=STL_HEADER)
    header["face_count"] = len(faces)
    if not len(faces):
        return header.tobytes()
    corners = np.asarray(vertices, np.float64)[faces]
    unit, valid = triangles.normals(triangles=corners, crosses=triangles.cross(corners))
    records = np.zeros(len(faces), dtype=STL_RECORD)
    if valid.all():
        records["normals"] = unit
    else:
        normals = np.zeros((len(faces), 3))
        normals[valid] = unit
        records["normals"] = normals
    records["vertices"] = corners
    return header.tobytes() + records.tobytes()
