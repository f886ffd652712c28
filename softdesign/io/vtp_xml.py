"""A VMTK centerline's XML PolyData (.vtp) read with numpy, zlib and the XML parser alone: no vtk import.

``softdesign validate`` opens every input, and importing vtk for one small
centerline was about 0.16 s of its start.  This reader takes the files VMTK and
vtk's writers make: one ``<Piece>``, little-endian, each ``<DataArray>`` inline
as ``ascii`` or ``binary`` (base64), uncompressed or zlib-compressed
(``vtkZLibDataCompressor``), with UInt32 or UInt64 headers.  The binary layout
is vtk's: uncompressed, a header giving the byte count, then the bytes, in one
base64 stream; compressed, a header (block count, block size, last block's
size, each block's compressed size) in its own base64 stream, then the blocks.

Anything else (appended data, another compressor, big-endian, counts or cell
ids that do not add up, bytes that do not decode) gives None, and the caller
reads the file with vtk (:mod:`softdesign.io.vtk_polydata`), whose messages
name what is wrong: so a file is refused here exactly as before.  The arrays
are vtk's own (``tests/io/test_vtp_xml.py`` compares them on the project's
and the VMTK files and on every layout vtk writes).
"""

from __future__ import annotations

import base64
import binascii
import math
import xml.etree.ElementTree as ET
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: vtk's XML type names and their numpy dtypes (little-endian).
DTYPES = {"Float32": "<f4", "Float64": "<f8", "Int8": "i1", "UInt8": "u1", "Int16": "<i2", "UInt16": "<u2",
          "Int32": "<i4", "UInt32": "<u4", "Int64": "<i8", "UInt64": "<u8"}
#: Cell blocks of a Piece and the names ``file_facts`` gives their counts.
CELL_BLOCKS = (("Lines", "lines"), ("Polys", "polygons"), ("Strips", "triangle strips"), ("Verts", "vertices"))


class _NotSimple(Exception):
    """The file is not one this reader takes: vtk reads it instead."""


@dataclass(frozen=True)
class PolyDataArrays:
    """What a PolyData file holds, as :func:`softdesign.io.vtk_polydata.polydata_arrays` and the cell counts give it.

    Attributes
    ----------
    points : (n, 3) float64, file units
    point_arrays, cell_arrays : named data arrays, (n,) or (n, components), their stored dtype
    lines : point ids of each line cell, in cell order
    cell_counts : cells per block by ``CELL_BLOCKS``' names
    """

    points: np.ndarray
    point_arrays: dict[str, np.ndarray]
    cell_arrays: dict[str, np.ndarray]
    lines: list[np.ndarray]
    cell_counts: dict[str, int] = field(default_factory=dict)


def read_simple_vtp(path: Path) -> PolyDataArrays | None:
    """The file's points, arrays and line cells, or None when it is not a simple one (see the module notes).

    The caller has checked the header's declared counts (:func:`~softdesign.io.vtk_header_bounds.check_vtk_header`).
    """
    try:
        return _read(ET.parse(path).getroot())
    except (_NotSimple, ET.ParseError, binascii.Error, zlib.error, ValueError, KeyError, TypeError, OverflowError):
        return None


def _read(root: ET.Element) -> PolyDataArrays:
    if (root.tag != "VTKFile" or root.get("type") != "PolyData" or root.get("byte_order", "LittleEndian")
            != "LittleEndian" or root.get("compressor", "vtkZLibDataCompressor") != "vtkZLibDataCompressor"):
        raise _NotSimple
    header = {"UInt32": "<u4", "UInt64": "<u8"}[root.get("header_type", "UInt32")]
    compressed = root.get("compressor") is not None
    pieces = root.findall("./PolyData/Piece")
    if len(pieces) != 1 or root.find("AppendedData") is not None:
        raise _NotSimple
    piece = pieces[0]
    count = int(piece.get("NumberOfPoints", "0"))

    def arrays(block: ET.Element | None, rows: int) -> dict[str, np.ndarray]:
        found = {}
        for element in [] if block is None else block.findall("DataArray"):
            name = element.get("Name")
            if name:
                found[name] = _data_array(element, header, compressed, rows)
        return found

    points_element = piece.find("./Points/DataArray")
    if count == 0 or points_element is None:
        raise _NotSimple  # no points: vtk's reading and messages
    points = _data_array(points_element, header, compressed, count).astype(np.float64)
    if points.shape != (count, 3):
        raise _NotSimple
    cells: dict[str, list[np.ndarray]] = {}
    for tag, name in CELL_BLOCKS:
        cells[name] = _cells(piece.find(tag), int(piece.get(f"NumberOf{tag}", "0")), header, compressed, count)
    total = sum(len(c) for c in cells.values())
    return PolyDataArrays(points, arrays(piece.find("PointData"), count), arrays(piece.find("CellData"), total),
                          cells["lines"], {name: len(cells[name]) for _, name in CELL_BLOCKS})


def _cells(block: ET.Element | None, count: int, header: str, compressed: bool, points: int) -> list[np.ndarray]:
    """Point ids per cell of one cell block (end offsets into its connectivity, as vtk's XML stores them)."""
    if count == 0:
        return []
    if block is None:
        raise _NotSimple
    named = {e.get("Name"): e for e in block.findall("DataArray")}
    ids = _data_array(named["connectivity"], header, compressed, None).astype(np.int64).reshape(-1)
    ends = _data_array(named["offsets"], header, compressed, count).astype(np.int64).reshape(-1)
    starts = np.concatenate([[0], ends[:-1]])
    if (len(ends) != count or np.any(ends < starts) or ends[-1] != len(ids)
            or (len(ids) and (ids.min() < 0 or ids.max() >= points))):
        raise _NotSimple  # vtk's messages (check_cell_indices) say what is wrong
    return [ids[s:e] for s, e in zip(starts.tolist(), ends.tolist(), strict=True)]


def _data_array(element: ET.Element, header: str, compressed: bool, rows: int | None) -> np.ndarray:
    """One DataArray's values, (rows,) or (rows, components) in its stored dtype; rows None: as many as it holds."""
    dtype = np.dtype(DTYPES[element.get("type", "")])
    components = int(element.get("NumberOfComponents", "1"))
    text = "".join((element.text or "").split())
    form = element.get("format")
    if form == "ascii":
        values = np.array((element.text or "").split(), dtype=dtype)
    elif form == "binary":
        data = _binary(text, np.dtype(header), compressed)
        if len(data) % dtype.itemsize:
            raise _NotSimple
        values = np.frombuffer(data, dtype=dtype).copy()
    else:
        raise _NotSimple  # appended data
    if components < 1 or len(values) % components or (rows is not None and len(values) != rows * components):
        raise _NotSimple
    return values.reshape(-1, components) if components > 1 else values


def _binary(text: str, header: np.dtype, compressed: bool) -> bytes:
    """The bytes of one inline binary DataArray (see the module notes for vtk's layouts)."""
    size = header.itemsize
    if not compressed:
        raw = base64.b64decode(text, validate=True)
        length = int(np.frombuffer(raw[:size], header)[0])
        if len(raw) != size + length:
            raise _NotSimple
        return raw[size:]
    blocks = int(np.frombuffer(base64.b64decode(text[: 4 * math.ceil(size / 3)])[:size], header)[0])
    chars = 4 * math.ceil((3 + blocks) * size / 3)
    head = np.frombuffer(base64.b64decode(text[:chars], validate=True)[: (3 + blocks) * size], header)
    block_size, last_size, sizes = int(head[1]), int(head[2]), head[3:].astype(np.int64)
    body = base64.b64decode(text[chars:], validate=True)
    if int(sizes.sum()) != len(body):
        raise _NotSimple
    out = []
    for k, end in enumerate(np.cumsum(sizes).tolist()):
        piece = zlib.decompress(body[end - int(sizes[k]):end])
        expected = last_size if k == blocks - 1 and last_size else block_size
        if len(piece) != expected:
            raise _NotSimple
        out.append(piece)
    return b"".join(out)
