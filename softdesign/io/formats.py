"""The one registry of mesh file formats: suffix -> reader, writer, whether it carries region labels.

Every place that names a mesh format takes it from :data:`FORMATS`: the case
file's ``export.formats``, the export stage, ``pose --output``, the
regression check's mesh files and the input surface reader.  .stl (binary),
.ply, .obj and .glb go through trimesh, .vtp and .vtk through vtk; .vtk is read
only (VMTK's legacy surfaces).

Writing is atomic (a temporary name, then a rename), and the bytes depend only
on the arrays (neither library writes timestamps), so the same mesh always
gives the same file.  PLY keeps a per-face ``region`` label and VTP a
``Region`` cell array (wall, caps, chamber, port, with the names in the field
array ``RegionNames``) when labels are given; the other formats drop them.
Reading merges the vertices that faces share (STL stores none), so a closed
surface reads as a closed mesh.

Units (:data:`FILE_UNITS`): glTF 2.0 defines its unit as the metre, so .glb is
written in metres (mm x 0.001 at write time) and read back into mm; Blender and
glTF viewers then show the body at its true size.  STL, PLY and OBJ carry no
unit and are written in mm, the convention of slicers and CAD imports (a
Blender user imports them with scale 0.001); .vtp is in mm as VMTK and 3D
Slicer expect.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.atomic import write_bytes_atomically
from softdesign.types import Mapper

Mesh = tuple[np.ndarray, np.ndarray]
#: Encodes (vertices (V, 3) mm, faces (F, 3), regions (F,) or None) as the file's bytes.
Encoder = Callable[[np.ndarray, np.ndarray, "np.ndarray | None"], bytes]


@dataclass(frozen=True)
class MeshFormat:
    """One mesh file format.

    Attributes
    ----------
    name : the suffix without its dot, as the case file names it (``stl``)
    description : what the file holds, for messages and help
    read : (path, the file's mm per unit, a mapper or None) -> (vertices (V, 3) float64 in the file's units,
        faces (F, 3) int64), shared vertices merged within MERGE_TOLERANCE_MM whatever the unit; empty arrays when
        the file holds no triangles.  With a mapper a large binary STL's vertex merge runs in two halves on it (the
        same arrays: :func:`~softdesign.geometry.rows.rows_in_first_order`); other files merge here
    encode : the writer's bytes, or None for a format that is only read
    carries_regions : whether the file keeps a region label per face
    unit : the length unit of the file's coordinates (the package converts from and to mm)
    """

    name: str
    description: str
    read: Callable[[Path, float, Mapper | None], Mesh]
    encode: Encoder | None
    carries_regions: bool = False
    unit: str = "mm"

    @property
    def suffix(self) -> str:
        """``.stl``"""
        return f".{self.name}"


#: Vertices of a file closer than this are one (trimesh's default, 1e-8, in mm rather than in the file's units: at
#: 1e-8 m, a surface in metres merged vertices 0.01 micrometre apart into edges of three triangles).
MERGE_TOLERANCE_MM = 1e-8


def _merge_digits(scale_to_mm: float) -> int:
    """Decimals to which trimesh rounds a coordinate in the file's units to merge within MERGE_TOLERANCE_MM."""
    return max(0, round(-math.log10(MERGE_TOLERANCE_MM / scale_to_mm)))


def _read_trimesh(path: Path, scale_to_mm: float = 1.0, mapper: Mapper | None = None) -> Mesh:
    import trimesh

    from softdesign.io.input_checks import stl_problem

    stl = path.suffix.lower() == ".stl"
    problem = stl_problem(path) if stl else None
    if problem is not None:
        raise InputDataError(f"{path}: not an STL file: {problem}; re-export the mesh as STL")
    try:
        if stl and (corners := _binary_stl(path)) is not None:  # the common case, without a trimesh.Trimesh
            _refuse_non_finite(path, corners[0])
            # trimesh's binary loader numbers the corners in order: face f is corners 3 f, 3 f + 1, 3 f + 2
            return _merged_as_trimesh_merges(*corners, _merge_digits(scale_to_mm), mapper, in_order=True)
        mesh = _load_stl(path) if stl else trimesh.load(str(path), force="mesh", process=False)
    except InputDataError:
        raise
    except Exception as err:  # trimesh raises many types for malformed files
        raise InputDataError(f"{path}: cannot read the mesh ({type(err).__name__}: {err}); re-export it") from err
    if not isinstance(mesh, trimesh.Trimesh):
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    _refuse_non_finite(path, np.asarray(mesh.vertices))
    # after the check (trimesh's processing drops non-finite vertices, and their faces, silently); what process()
    # does, with the merge's rounding in mm
    mesh.merge_vertices(digits_vertex=_merge_digits(scale_to_mm))
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


def _binary_stl(path: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """A binary STL's corners (3F, 3) as stored (float32) and faces (F, 3) int64 as trimesh's binary loader reads
    them; None for an ASCII or empty one (then :func:`_load_stl`).  The corners stay float32: the merge widens
    them a block at a time (:func:`_merge_keys`) and only its vertices whole, each to the same float64."""
    from trimesh.exchange.stl import HeaderError, load_stl_binary

    with path.open("rb") as handle:
        try:
            loaded = load_stl_binary(handle)
        except HeaderError:  # not a binary STL: ASCII
            return None
    if "vertices" not in loaded or "faces" not in loaded or not len(loaded["faces"]):
        return None
    return np.asarray(loaded["vertices"]), np.asarray(loaded["faces"], np.int64)


def _merged_as_trimesh_merges(vertices: np.ndarray, faces: np.ndarray, digits: int, mapper: Mapper | None = None,
                              in_order: bool = False) -> Mesh:
    """``trimesh.Trimesh(vertices, faces, process=False).merge_vertices(digits_vertex=digits)``'s vertices and faces
    for a mesh without normals or texture (a binary STL's), in about half its time.

    Vertices are one when their coordinates times 10^digits round to the same integers; each merged vertex is
    the first of its group, in the order of first occurrence among the vertices that faces use (what trimesh
    keeps): the same arrays, bit for bit (tests/io/test_stl_merge.py compares them), with or without a ``mapper``
    (:func:`~softdesign.geometry.rows.rows_in_first_order`).
    ``in_order``: ``faces`` is ``arange(len(vertices)).reshape(-1, 3)`` (a binary STL's corners, each face's own),
    so that every vertex is used and the faces are the merged numbering reshaped: no scatter or gather of 3 F ids.
    ``vertices`` may be float32 (a binary STL's, as stored): the merged ones come back float64, each the same number.
    """
    from softdesign.geometry.rows import rows_in_first_order

    if in_order:
        first, inverse_used = rows_in_first_order(_merge_keys(vertices, digits), mapper)
        return np.asarray(vertices[first], np.float64), inverse_used.reshape(faces.shape)
    referenced = np.zeros(len(vertices), bool)
    referenced[faces] = True
    if referenced.all():  # every corner is a face's: the vertices as they are, no gather
        first, inverse_used = rows_in_first_order(_merge_keys(vertices, digits), mapper)
        return np.asarray(vertices[first], np.float64), inverse_used[faces]
    used = np.flatnonzero(referenced)
    first, inverse_used = rows_in_first_order(_merge_keys(vertices[used], digits), mapper)
    inverse = np.zeros(len(vertices), np.int64)
    inverse[used] = inverse_used
    return np.asarray(vertices[used[first]], np.float64), inverse[faces]


#: Rows of the vertices :func:`_merge_keys` scales at a time: its float64 block (768 kB) stays in a core's cache.
MERGE_BLOCK_ROWS = 1 << 15


def _merge_keys(vertices: np.ndarray, digits: int) -> np.ndarray:
    """(V, 3) int64, trimesh's merge keys: the coordinates (float32 or float64) as float64 times 10^digits,
    rounded: ``(vertices.astype(float) * 10.0**digits).round().astype(int)``'s numbers, a block of rows at a time.

    Each number is its own, so the blocks change none; the whole (V, 3) float64 arrays of the plain expression
    (three on a binary STL's 3M corners, 216 MB of fresh memory) cost ten times the arithmetic.
    """
    keys = np.empty(vertices.shape, np.int64)
    block = np.empty((min(MERGE_BLOCK_ROWS, len(vertices)),) + vertices.shape[1:])
    scale = 10.0**digits
    for start in range(0, len(vertices), MERGE_BLOCK_ROWS):
        rows = slice(start, min(start + MERGE_BLOCK_ROWS, len(vertices)))
        scaled = block[: rows.stop - start]
        scaled[...] = vertices[rows]  # float32 widens exactly
        scaled *= scale
        scaled.round(out=scaled)
        np.copyto(keys[rows], scaled, casting="unsafe")  # whole numbers: astype(int64)'s
    return keys


def _load_stl(path: Path) -> object:
    """The STL as trimesh.load reads it (one Trimesh, vertices merged); a binary one built once.

    trimesh.load puts the mesh in a scene, then concatenates the scene into a copy of it; a binary STL
    (one solid) is built straight from trimesh's binary STL loader instead.  ASCII files (maybe several
    solids) and empty ones still go through trimesh.load.
    """
    import trimesh
    from trimesh.exchange.stl import HeaderError, load_stl_binary

    with path.open("rb") as handle:
        try:
            loaded = load_stl_binary(handle)
        except HeaderError:  # not a binary STL: ASCII
            loaded = {}
    if "vertices" not in loaded or "faces" not in loaded:
        return trimesh.load(str(path), force="mesh", process=False)
    return trimesh.Trimesh(vertices=loaded["vertices"], faces=loaded["faces"], process=False)


def _refuse_non_finite(path: Path, vertices: np.ndarray) -> None:
    """InputDataError naming how many vertices have a NaN or infinite coordinate (the first one too)."""
    if np.isfinite(vertices).all():  # the common case, without a row-wise pass
        return
    bad = ~np.all(np.isfinite(vertices), axis=1)
    if bad.any():
        raise InputDataError(f"{path}: {int(bad.sum())} of its {len(vertices)} vertices have NaN or infinite "
                             f"coordinates (the first: vertex {int(np.argmax(bad))} as stored); expected finite "
                             "coordinates: re-export the surface, or repair it (e.g. vmtksurfacecleaner)")


def _read_vtk(path: Path, scale_to_mm: float = 1.0, mapper: Mapper | None = None) -> Mesh:
    # merges exact duplicates only, in any unit, here (the mapper serves a binary STL's merge)
    from softdesign.io.vtk_polydata import read_polydata, triangles_from_polydata

    vertices, faces = triangles_from_polydata(read_polydata(path))
    _refuse_non_finite(path, vertices)
    return _merge_duplicate_vertices(vertices, faces)


def _merge_duplicate_vertices(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    if len(vertices) == 0:
        return vertices, faces
    from softdesign.geometry.rows import distinct_rows

    distinct = distinct_rows(vertices)  # np.unique(vertices, axis=0)'s arrays, in 40 % of its time
    unique, inverse = distinct.rows, distinct.inverse
    referenced = np.zeros(len(unique), bool)
    referenced[inverse.reshape(-1)[faces]] = True
    used = np.flatnonzero(referenced)  # np.unique(inverse[faces]): numpy 2.4 hashes 3 F integers, 15 times slower
    remap = np.full(len(unique), -1, np.int64)
    remap[used] = np.arange(len(used))
    return unique[used], remap[inverse.reshape(-1)[faces]]


def _trimesh_encoder(file_type: str) -> Encoder:
    def encode(vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None) -> bytes:
        import trimesh

        mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)
        if regions is not None and file_type == "ply":
            mesh.face_attributes["region"] = np.asarray(regions, np.int8)
            data = trimesh.exchange.ply.export_ply(mesh, encoding="binary", include_attributes=True)
        else:
            data = trimesh.exchange.export.export_mesh(mesh, file_obj=None, file_type=file_type)
        return data.encode("utf-8") if isinstance(data, str) else bytes(data)

    return encode


def _stl_bytes(vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None) -> bytes:
    """Binary STL, trimesh's bytes (:mod:`softdesign.io.stl_bytes`); STL carries no regions."""
    from softdesign.io.stl_bytes import binary_stl_bytes

    return binary_stl_bytes(vertices, faces)


#: mm per metre: glTF's coordinates are metres.
MM_PER_M = 1000.0


def _read_glb(path: Path, scale_to_mm: float = 1.0, mapper: Mapper | None = None) -> Mesh:
    vertices, faces = _read_trimesh(path, MM_PER_M, mapper)
    return vertices * MM_PER_M, faces


def _glb_bytes(vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None) -> bytes:
    """Binary glTF in metres, as the glTF 2.0 specification requires (softdesign's mm / 1000)."""
    return _trimesh_encoder("glb")(np.asarray(vertices, float) / MM_PER_M, faces, regions)


def _vtp_bytes(vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None) -> bytes:
    """VTK XML PolyData of the triangles, binary (base64) and zlib-compressed, as VMTK writes it."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonCore import vtkStringArray

    from softdesign.io.vtk_polydata import polydata_writer
    from softdesign.meshing.tessellate import Region
    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    poly = polydata_from_triangles(np.asarray(vertices, float), np.asarray(faces, np.int64))
    if regions is not None:
        labels = numpy_to_vtk(np.ascontiguousarray(regions, dtype=np.int32), deep=True)
        labels.SetName("Region")
        poly.GetCellData().AddArray(labels)
        names = vtkStringArray()
        names.SetName("RegionNames")
        for region in Region:  # value i is names[i]
            names.InsertNextValue(region.name.lower())
        poly.GetFieldData().AddArray(names)
    writer = polydata_writer(poly)
    writer.WriteToOutputStringOn()
    if writer.Write() != 1:
        raise OSError("vtk could not encode the mesh as .vtp")
    return writer.GetOutputString().encode("ascii")


#: Every mesh format by name, in the order messages list them.
FORMATS: dict[str, MeshFormat] = {
    f.name: f
    for f in (
        MeshFormat("stl", "binary STL (float32 corners, no shared vertices)", _read_trimesh, _stl_bytes),
        MeshFormat("ply", "binary PLY with a region label per face", _read_trimesh, _trimesh_encoder("ply"), True),
        MeshFormat("obj", "Wavefront OBJ (text)", _read_trimesh, _trimesh_encoder("obj")),
        MeshFormat("glb", "binary glTF 2.0 in metres, for viewers", _read_glb, _glb_bytes, unit="m"),
        MeshFormat("vtp", "VTK XML PolyData (binary, zlib) with a Region cell array", _read_vtk, _vtp_bytes, True),
        MeshFormat("vtk", "legacy VTK PolyData (read only)", _read_vtk, None),
    )
}
#: The length unit of each format's files (the manifest records it in ``metrics.export.units``).
FILE_UNITS = {name: f.unit for name, f in FORMATS.items()}
#: Formats a mesh can be written in: ``export.formats`` and ``pose --output``.
MESH_FORMATS = tuple(name for name, f in FORMATS.items() if f.encode is not None)


def mesh_bytes(vertices: np.ndarray, faces: np.ndarray, file_type: str, regions: np.ndarray | None = None) -> bytes:
    """The encoded file for ``file_type`` in MESH_FORMATS; ``regions`` (F,) is kept where the format carries it."""
    found = FORMATS.get(file_type)
    if found is None or found.encode is None:
        raise ValueError(f"mesh format must be one of {', '.join(MESH_FORMATS)}, got {file_type!r}")
    return found.encode(vertices, faces, regions if found.carries_regions else None)


def write_mesh(path: str | Path, vertices: np.ndarray, faces: np.ndarray, regions: np.ndarray | None = None) -> Path:
    """Write a mesh (format from the suffix) under a temporary name, then rename."""
    path = Path(path)
    return write_bytes_atomically(path, mesh_bytes(vertices, faces, path.suffix.lower().lstrip("."), regions))


def read_mesh(path: str | Path) -> Mesh:
    """Vertices (V, 3) float64 mm and faces (F, 3) int64 of a mesh file (format from the suffix).

    Raises
    ------
    InputDataError
        An unknown suffix (the message lists the formats), an unreadable file, or no triangles.
    """
    path = Path(path)
    found = FORMATS.get(path.suffix.lower().lstrip("."))
    if found is None:
        choices = ", ".join(f.suffix for f in FORMATS.values())
        raise InputDataError(f"{path}: unknown mesh format '{path.suffix}'; expected one of {choices}")
    vertices, faces = found.read(path, 1.0, None)
    if len(faces) == 0:
        raise InputDataError(f"{path}: the mesh has no triangles")
    return vertices, faces
