"""Read centerline files into a :class:`CenterlineNetwork` (mm).

Formats, by suffix: ``.vtp`` (VTK XML PolyData, as VMTK writes it,
zlib-compressed binary included), ``.vtk`` (legacy PolyData or unstructured
grid), ``.vtu`` (XML unstructured grid), ``.csv`` (a
header row naming ``x, y, z`` and optionally ``radius``) and ``.npy`` (an
(n, 3) or (n, 4) array, the 4th column a radius).  CSV and NPY files hold
one polyline.  Line cells that are all 2-point segments, and every
unstructured grid's lines (gmsh's export of VMTK centerlines), are joined into
one path from the inlet to each outlet (:mod:`softdesign.io.centerline_segments`).
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError
from softdesign.geometry.network import TRACT_KEYS, CenterlineNetwork, Polyline
from softdesign.io.centerline_segments import (
    LineCells,
    all_two_point,
    is_unstructured_grid,
    polylines_from_segments,
    read_line_cells,
)
from softdesign.io.input_checks import check_input_file, check_npy_header
from softdesign.io.vtk_polydata import polydata_arrays, read_polydata, simple_vtp

RADIUS_KEY = "MaximumInscribedSphereRadius"


#: Most points a .csv or .npy centerline may hold (a VTK file's counts are bounded by its header: vtk_header_bounds).
#: A VMTK centerline has a few thousand points and the build resamples it to at most 50,000; a million read rows
#: cost about 200 MB as the CSV is parsed (12 million .npy points passed 6.2 GB before).
MAX_CENTERLINE_POINTS = 1_000_000

def read_centerline_network(path: str | Path, scale_to_mm: float = 1.0) -> CenterlineNetwork:
    """Read every polyline of a centerline file.

    Parameters
    ----------
    path : file with suffix .vtp, .vtk, .vtu, .csv or .npy
    scale_to_mm : factor from the file's units to mm (10 for cm, 1000 for m)

    Raises
    ------
    InputDataError
        Missing or unreadable file, unknown suffix, no lines in the file.
    """
    path = Path(path)
    reader = _READERS.get(path.suffix.lower())
    if reader is None:
        raise InputDataError(
            f"{path}: unknown centerline format '{path.suffix}'; expected one of "
            f"{', '.join(sorted(_READERS))} (convert it, e.g. with vmtkcenterlines -ofile x.vtp)"
        )
    check_input_file(path, "centerline")
    lines, notes = reader(path)
    if not lines:
        raise InputDataError(
            f"{path}: the file has no polylines (no lines); expected VMTK centerlines "
            "(vmtkcenterlines output), not a surface or a point cloud"
        )
    for number, line in enumerate(lines):
        bad = ~np.isfinite(line.points).all(axis=1)
        if line.radius is not None:
            bad |= ~np.isfinite(line.radius)
        if bad.any():
            raise InputDataError(
                f"{path}: polyline {number} has NaN or infinite values at point {int(np.flatnonzero(bad)[0])} "
                f"({int(bad.sum())} point(s)); expected finite coordinates and radii: fix or remove those points"
            )
    scaled = tuple(
        Polyline(line.points * scale_to_mm, None if line.radius is None else line.radius * scale_to_mm, line.cell_data)
        for line in lines
    )
    return CenterlineNetwork(scaled, source=str(path), notes=notes)


def _read_vtk_lines(path: Path) -> tuple[list[Polyline], tuple[str, ...]]:
    if is_unstructured_grid(path):
        return _joined(read_line_cells(path), path)
    simple = simple_vtp(path)  # a VMTK .vtp without importing vtk (validate's start-up), else vtk's reader
    if simple is not None:
        points, point_arrays, cell_arrays, cells = simple.points, simple.point_arrays, simple.cell_arrays, simple.lines
    else:
        poly = read_polydata(path)
        points, point_arrays, cell_arrays = polydata_arrays(poly)
        cells = _line_cells(poly)
    if all_two_point(cells):
        return _joined(LineCells("VTK PolyData", points, cells, point_arrays, cell_arrays), path)
    radius_all = point_arrays.get(RADIUS_KEY)
    lines = []
    for cell_index, ids in enumerate(cells):
        radius = None if radius_all is None else np.array(radius_all[ids], float).reshape(-1)
        cell_data = {k: int(cell_arrays[k][cell_index]) for k in TRACT_KEYS if k in cell_arrays}
        lines.append(Polyline(np.array(points[ids], float), radius, cell_data))
    return lines, ()


def _joined(lines: LineCells, path: Path) -> tuple[list[Polyline], tuple[str, ...]]:
    polylines, note = polylines_from_segments(lines, RADIUS_KEY, str(path))
    return polylines, (note,) if note else ()


def _line_cells(poly) -> list[np.ndarray]:
    """Point ids of each line/polyline cell, in cell order (other cell types skipped)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if poly.GetNumberOfLines() == 0:
        return []
    conn = poly.GetLines()
    offsets = vtk_to_numpy(conn.GetOffsetsArray()).astype(np.int64)
    ids = vtk_to_numpy(conn.GetConnectivityArray()).astype(np.int64)
    return [ids[a:b] for a, b in zip(offsets[:-1], offsets[1:], strict=True) if b - a >= 1]


def _check_points(path: Path, count: int, what: str) -> None:
    """InputDataError when a centerline file holds more than MAX_CENTERLINE_POINTS points."""
    if count > MAX_CENTERLINE_POINTS:
        raise InputDataError(f"{path}: {count:,} {what}, above the bound of {MAX_CENTERLINE_POINTS:,} centerline "
                             "points (a VMTK centerline has a few thousand); resample it (e.g. "
                             "vmtkcenterlineresampling)")


def _line_count(path: Path) -> int:
    """Lines of a text file, counted in 1 MB chunks without decoding or keeping them."""
    count = 0
    with path.open("rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            count += chunk.count(b"\n")
    return count


def _read_csv(path: Path) -> list[Polyline]:
    try:
        _check_points(path, _line_count(path) - 1, "rows")  # before parsing: 9M rows took 143 s and 3.5 GB
        with path.open(newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError, csv.Error) as err:  # csv.Error: a field over 128 kB, a NUL byte
        raise InputDataError(f"{path}: cannot read the CSV centerline ({err}); save it as plain CSV") from err
    if not rows:
        raise InputDataError(f"{path}: the CSV file is empty; expected a header row 'x,y,z[,radius]' and points")
    header = [h.strip().lower() for h in rows[0]]
    missing = [k for k in ("x", "y", "z") if k not in header]
    if missing:
        raise InputDataError(
            f"{path}: the header row must name x, y, z (and optionally radius), got {rows[0]}; add the header"
        )
    cols = [header.index(k) for k in ("x", "y", "z")] + ([header.index("radius")] if "radius" in header else [])
    values = np.array([_csv_row(path, n + 2, row, cols) for n, row in enumerate(rows[1:]) if row], float)
    if values.size == 0:
        return []
    return [Polyline(values[:, :3], values[:, 3] if values.shape[1] == 4 else None)]


def _csv_row(path: Path, line: int, row: list[str], cols: list[int]) -> list[float]:
    try:
        return [float(row[c]) for c in cols]
    except (ValueError, IndexError):
        raise InputDataError(f"{path}:{line}: expected {len(cols)} numbers, got {row}; fix or remove the row") from None


def _read_npy(path: Path) -> list[Polyline]:
    shape = check_npy_header(path)
    _check_points(path, shape[0] if shape else 1, f"rows in its {shape} array")
    try:
        values = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as err:
        raise InputDataError(f"{path}: cannot read the .npy centerline ({err})") from err
    if values.ndim != 2 or values.shape[1] not in (3, 4):
        raise InputDataError(
            f"{path}: expected an (n, 3) or (n, 4) array (x, y, z[, radius]), got shape {values.shape}"
        )
    values = values.astype(float)
    return [Polyline(values[:, :3], values[:, 3] if values.shape[1] == 4 else None)] if len(values) else []


_READERS: dict[str, Callable[[Path], tuple[list[Polyline], tuple[str, ...]]]] = {
    ".vtp": _read_vtk_lines,
    ".vtk": _read_vtk_lines,
    ".vtu": _read_vtk_lines,
    ".csv": lambda path: (_read_csv(path), ()),
    ".npy": lambda path: (_read_npy(path), ()),
}
