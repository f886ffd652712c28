"""The counts a VTK file declares, checked against its size and the memory budget before vtk allocates them.

vtk's readers allocate what a header declares before they read a byte of the
data: an XML ``.vtp`` whose ``<Piece NumberOfPoints="10000000000000">`` sits
in a 1 kB file aborts the process natively (``std::bad_alloc``, exit 134, no
message).  :func:`check_vtk_header` reads the declared counts from the
header only (the XML attributes before the data, or the legacy keywords
``POINTS n`` and ``LINES n size``), and refuses, naming the file, the count
and the fix:

* a count above :data:`MAX_DECLARED_ITEMS` (what the memory budget affords
  for an input: see below);
* counts whose data cannot fit in the file (and, once read, cells naming points
  the file does not have: :func:`check_cell_indices`): a legacy file stores every
  number (at least 2 bytes as text, 4 as binary); an XML file may compress
  its data with zlib, which shrinks at most :data:`ZLIB_MOST_RATIO` times.

Why 10 million: an input point costs about 24 bytes in vtk (float64 x 3), 24
again as a numpy copy and some 50 more in trimesh's or the centerline's
arrays, about 100 bytes in all; 10 million points are 1 GB, half of
:data:`~softdesign.limits.MEMORY_BUDGET_BYTES`, beside the build's own
peaks.  The largest VMTK surfaces of whole aortas have about a million.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from softdesign.errors import InputDataError
from softdesign.limits import MEMORY_BUDGET_TEXT

#: Most points, or cells, or connectivity entries an input VTK file may declare (see the module's text).
MAX_DECLARED_ITEMS = 10_000_000
#: How many times zlib can shrink data at most (its deflate format's limit is about 1032:1).
ZLIB_MOST_RATIO = 1100
#: How much of an XML file's head is searched for its ``<Piece ...>`` counts, bytes.
XML_HEAD_BYTES = 1 << 20
#: Fewest bytes one number takes in a legacy file: a digit and a separator as text (4 as binary float).
LEGACY_NUMBER_BYTES = 2
#: Fewest bytes one number of XML data takes before compression (a float32 or int32; text takes more).
XML_NUMBER_BYTES = 4

_XML_COUNT = re.compile(rb'NumberOf(Points|Verts|Lines|Strips|Polys|Cells)\s*=\s*"\s*([^"]*)"')
_LEGACY_COUNT = re.compile(rb"^(POINTS|VERTICES|LINES|POLYGONS|TRIANGLE_STRIPS|CELLS)[ \t]+(\S+)(?:[ \t]+(\S+))?",
                           re.MULTILINE)


def check_vtk_header(path: Path) -> None:
    """InputDataError when ``path`` (.vtp, .vtu or legacy .vtk) declares counts beyond its size or the budget.

    Reads the header only (for a legacy file, its keyword lines); a file whose header declares nothing (not
    VTK at all) is left to the reader's own message.
    """
    size = path.stat().st_size
    if path.suffix.lower() == ".vtk":
        counts = _legacy_counts(path)
        capacity, how = size // LEGACY_NUMBER_BYTES, "even as one-digit text"
    else:
        counts = _xml_counts(path)
        capacity, how = size * ZLIB_MOST_RATIO // XML_NUMBER_BYTES, "even compressed at zlib's best"
    for name, count, _ in counts:
        if count > MAX_DECLARED_ITEMS:
            raise InputDataError(
                f"{path}: declares {count:,} {name}, above the {MAX_DECLARED_ITEMS:,} an input may have within the "
                f"{MEMORY_BUDGET_TEXT} memory budget; expected a vessel surface or centerline of at most "
                f"{MAX_DECLARED_ITEMS:,}: decimate it (vmtksurfacedecimation), or check that the file is not corrupt"
            )
    numbers = sum(n for _, _, n in counts)
    if numbers > capacity:
        raise InputDataError(
            f"{path}: its header declares {', '.join(f'{c:,} {n}' for n, c, _ in counts)}, which need at least "
            f"{numbers:,} numbers, more than its {size:,} bytes can hold {how}; the file is truncated or corrupt: "
            "export it again from VMTK or ParaView"
        )


def _declared(name: bytes, text: bytes, path: Path) -> tuple[str, int]:
    try:
        count = int(text.decode("ascii").strip())
    except (UnicodeDecodeError, ValueError):
        count = -1
    label = name.decode("ascii")
    if count < 0 or len(text) > 20:
        raise InputDataError(f"{path}: declares {label} count {text[:40].decode('ascii', 'replace')!r}, expected a "
                             "whole number >= 0; the file is corrupt: export it again from VMTK or ParaView")
    return label, count


def _xml_counts(path: Path) -> list[tuple[str, int, int]]:
    """Each ``NumberOf...`` attribute's total over the pieces in the XML head, with the numbers it needs at least."""
    with path.open("rb") as handle:
        head = handle.read(XML_HEAD_BYTES)
    head = head.split(b"<AppendedData", 1)[0]
    totals: dict[str, int] = {}
    for match in _XML_COUNT.finditer(head):
        name, count = _declared(match.group(1), match.group(2), path)
        totals[name] = totals.get(name, 0) + count
    return [(name.lower(), count, count * (3 if name == "Points" else 1)) for name, count in totals.items()]


def _legacy_counts(path: Path) -> list[tuple[str, int, int]]:
    """``POINTS n`` and each cell section's ``n size``, from the keyword lines (read in chunks, never whole)."""
    found: list[tuple[str, int, int]] = []
    with path.open("rb") as handle:
        tail = b""
        while chunk := handle.read(XML_HEAD_BYTES):
            text = tail + chunk
            cut = text.rfind(b"\n") + 1 if len(chunk) == XML_HEAD_BYTES else len(text)  # whole lines only
            for match in _LEGACY_COUNT.finditer(text[:cut]):
                found.append(_legacy_item(match, path))
            tail = text[cut:][-256:]
    return found


def _legacy_item(match: re.Match[bytes], path: Path) -> tuple[str, int, int]:
    """(keyword, count, numbers needed): 3 per point; a cell section's ``size`` entries (its counts included)."""
    name, count = _declared(match.group(1), match.group(2), path)
    if name == "POINTS":
        return "points", count, 3 * count
    entries = match.group(3)
    size = _declared(match.group(1), entries, path)[1] if entries is not None and entries.isdigit() else count
    return f"{name.lower()} cells", count, max(size, count)


def check_cell_indices(poly: Any, path: Path) -> None:
    """InputDataError when a cell of ``poly`` (vtkPolyData read from ``path``) names a point it does not have."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    count = poly.GetNumberOfPoints()
    for kind, cells in (("vertex", poly.GetVerts()), ("line", poly.GetLines()), ("polygon", poly.GetPolys()),
                        ("strip", poly.GetStrips())):
        if cells is None or cells.GetNumberOfCells() == 0:
            continue
        ids = vtk_to_numpy(cells.GetConnectivityArray())
        outside = (ids < 0) | (ids >= count)
        if outside.any():
            raise InputDataError(
                f"{path}: {int(outside.sum())} {kind} cell point index(es) out of range (e.g. {int(ids[outside][0])}; "
                f"the file has {count} points, indices 0 to {count - 1}); the file is corrupt: export it again "
                "from VMTK or ParaView"
            )
