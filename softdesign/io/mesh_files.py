"""Write meshes by suffix (.stl binary, .ply, .obj, .glb) through trimesh, atomically.

Bytes depend only on the arrays (trimesh writes no timestamps), so the same
mesh always gives the same file.  PLY keeps a per-face ``region`` label
(wall, caps, chamber, port) when one is given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdesign.io.atomic import write_bytes_atomically

MESH_FORMATS = ("stl", "ply", "obj", "glb")


def mesh_bytes(vertices: np.ndarray, faces: np.ndarray, file_type: str, regions: np.ndarray | None = None) -> bytes:
    """The encoded file for ``file_type`` in MESH_FORMATS."""
    import trimesh

    if file_type not in MESH_FORMATS:
        raise ValueError(f"mesh format must be one of {', '.join(MESH_FORMATS)}, got {file_type!r}")
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)
    if regions is not None and file_type == "ply":
        mesh.face_attributes["region"] = np.asarray(regions, np.int8)
        data = trimesh.exchange.ply.export_ply(mesh, encoding="binary", include_attributes=True)
    else:
        data = trimesh.exchange.export.export_mesh(mesh, file_obj=None, file_type=file_type)
    return data.encode("utf-8") if isinstance(data, str) else bytes(data)


def write_mesh(path: str | Path, vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None = None) -> Path:
    """Write a mesh (format from the suffix) under a temporary name, then rename."""
    path = Path(path)
    return write_bytes_atomically(path, mesh_bytes(vertices, faces, path.suffix.lower().lstrip("."), regions))
