"""Write meshes by suffix (.stl binary, .ply, .obj, .glb through trimesh; .vtp through vtk), atomically.

Bytes depend only on the arrays (neither library writes timestamps), so the
same mesh always gives the same file.  PLY keeps a per-face ``region`` label
and VTP a ``Region`` cell array (wall, caps, chamber, port, with the names in
the field array ``RegionNames``) when labels are given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdesign.io.atomic import write_bytes_atomically

MESH_FORMATS = ("stl", "ply", "obj", "glb", "vtp")
#: Formats that carry per-face region labels.
LABELLED_FORMATS = ("ply", "vtp")


def mesh_bytes(vertices: np.ndarray, faces: np.ndarray, file_type: str, regions: np.ndarray | None = None) -> bytes:
    """The encoded file for ``file_type`` in MESH_FORMATS."""
    import trimesh

    if file_type not in MESH_FORMATS:
        raise ValueError(f"mesh format must be one of {', '.join(MESH_FORMATS)}, got {file_type!r}")
    if file_type == "vtp":
        return _vtp_bytes(vertices, faces, regions)
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


def _vtp_bytes(vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None) -> bytes:
    """VTK XML PolyData of the triangles, binary (base64) and zlib-compressed, as VMTK writes it."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    from softdesign.io.vtk_polydata import polydata_from_triangles, polydata_writer
    from softdesign.meshing.tessellate import Region

    poly = polydata_from_triangles(np.asarray(vertices, float), np.asarray(faces, np.int64))
    if regions is not None:
        labels = numpy_to_vtk(np.ascontiguousarray(regions, dtype=np.int32), deep=True)
        labels.SetName("Region")
        poly.GetCellData().AddArray(labels)
        names = vtk.vtkStringArray()
        names.SetName("RegionNames")
        for region in Region:  # value i is names[i]
            names.InsertNextValue(region.name.lower())
        poly.GetFieldData().AddArray(names)
    writer = polydata_writer(poly)
    writer.WriteToOutputStringOn()
    if writer.Write() != 1:
        raise OSError("vtk could not encode the mesh as .vtp")
    return writer.GetOutputString().encode("ascii")
