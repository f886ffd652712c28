"""Compare regenerated vessel files with the committed ones by geometry, within a named tolerance.

The sample and cohort inputs under ``data/`` are the generators' output.  Their
bytes are the wrong test across environments: another numpy, scipy or vtk
release moves a coordinate by ~1e-14 mm, and the bytes change.  These helpers
compare what the files hold instead: the same polylines and triangles, the
same array names, and every coordinate and point value within
:data:`REGENERATION_TOL_MM`.  "Same inputs, same bytes" stays a test within one
environment (two builds in one run: ``tests/pipeline/test_build.py``).

A binary STL stores float32 (a step of about 8e-6 mm at 100 mm), so a 1e-14 mm
change can round a coordinate to the next float32: for an STL whose
coordinates are all float32 numbers, one float32 step is allowed on top of
the tolerance.  Changes smaller than that step cannot be seen in such a file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: How far a regenerated coordinate or point value may be from the committed one, mm.
REGENERATION_TOL_MM = 1e-9
#: Surface formats compared through trimesh (vertices and faces as stored, nothing merged).
SURFACE_SUFFIXES = (".stl", ".ply", ".obj")


def vessel_file_differences(
    produced: Path, committed: Path, scale_to_mm: float = 1.0, tol_mm: float = REGENERATION_TOL_MM
) -> list[str]:
    """What differs between two centerline (.vtp) or surface (.stl .ply .obj) files; [] when they agree.

    Parameters
    ----------
    produced, committed : the regenerated file and the committed one (same suffix)
    scale_to_mm : factor from the files' units to mm (10 for a file in cm)
    tol_mm : largest difference of a coordinate or point value, mm
    """
    produced, committed = Path(produced), Path(committed)
    suffix = committed.suffix.lower()
    if produced.suffix.lower() != suffix:
        return [f"suffixes differ: {produced.name} vs {committed.name}"]
    tol = tol_mm / scale_to_mm  # in the files' units
    if suffix == ".vtp":
        return centerline_differences(produced, committed, tol)
    if suffix in SURFACE_SUFFIXES:
        return surface_differences(produced, committed, tol)
    raise ValueError(f"{committed}: no comparison for '{suffix}'; expected .vtp or one of {SURFACE_SUFFIXES}")


def assert_same_vessel_file(
    produced: Path, committed: Path, scale_to_mm: float = 1.0, tol_mm: float = REGENERATION_TOL_MM
) -> None:
    """Fail, listing every difference, unless the two files agree within ``tol_mm``."""
    differences = vessel_file_differences(produced, committed, scale_to_mm, tol_mm)
    assert not differences, f"{produced} vs {committed} (tolerance {tol_mm:g} mm):\n  " + "\n  ".join(differences)


def centerline_differences(produced: Path, committed: Path, tol: float) -> list[str]:
    """Polylines (cells and point counts), point and cell array names, and values within ``tol``."""
    new, old = _read_lines(produced), _read_lines(committed)
    if new["lines"] != old["lines"]:
        return [f"polylines differ: point ids per line {_sizes(new['lines'])} vs {_sizes(old['lines'])}"]
    found = _values_differences("points", new["points"], old["points"], tol)
    for kind in ("point", "cell"):
        names_new, names_old = sorted(new[kind]), sorted(old[kind])
        if names_new != names_old:
            found.append(f"{kind} arrays differ: {names_new} vs {names_old}")
            continue
        for name in names_old:
            found += _values_differences(f"{kind} array {name}", new[kind][name], old[kind][name], tol)
    return found


def surface_differences(produced: Path, committed: Path, tol: float) -> list[str]:
    """Triangle and vertex counts, the faces exactly, every vertex within ``tol`` (plus a binary STL's float32 step)."""
    (v_new, f_new), (v_old, f_old) = _read_triangles(produced), _read_triangles(committed)
    if f_new.shape != f_old.shape or v_new.shape != v_old.shape:
        return [f"sizes differ: {len(f_new)} triangles, {len(v_new)} vertices vs {len(f_old)}, {len(v_old)}"]
    if not np.array_equal(f_new, f_old):
        return [f"faces differ: {int(np.any(f_new != f_old, axis=1).sum())} triangles use other vertices"]
    step = _float32_step(v_old) if committed.suffix.lower() == ".stl" else 0.0
    return _values_differences("vertices", v_new, v_old, tol, step)


def _values_differences(
    what: str, new: np.ndarray, old: np.ndarray, tol: float, step: np.ndarray | float = 0.0
) -> list[str]:
    """Differences of two arrays: shape and kind, integers exactly, floats within ``tol + step``."""
    new, old = np.asarray(new), np.asarray(old)
    if new.shape != old.shape or new.dtype.kind != old.dtype.kind:
        return [f"{what}: shape or kind differs: {new.shape} {new.dtype} vs {old.shape} {old.dtype}"]
    if new.dtype.kind not in "fc":
        return [] if np.array_equal(new, old) else [f"{what}: {int(np.sum(new != old))} values differ"]
    allowed = tol + step
    off = np.abs(new - old) > allowed
    if not off.any():
        return []
    worst = np.unravel_index(int(np.argmax(np.abs(new - old) - allowed)), old.shape)
    return [
        f"{what}: {int(off.sum())} of {off.size} values differ by more than {tol:g}; the worst at "
        f"{tuple(int(i) for i in worst)}: {new[worst]!r} vs {old[worst]!r}"
    ]


def _float32_step(values: np.ndarray) -> np.ndarray | float:
    """One float32 step at each value when every value is a float32 number (as in a binary STL); else 0."""
    values = np.asarray(values, np.float64)
    if values.size and np.array_equal(values.astype(np.float32).astype(np.float64), values):
        return np.spacing(np.abs(values).astype(np.float32)).astype(np.float64)
    return 0.0


def _read_lines(path: Path) -> dict:
    """The polylines (point ids per line), points, and point and cell arrays by name of a .vtp file."""
    from vtk.util.numpy_support import vtk_to_numpy

    from softdesign.io.vtk_polydata import polydata_arrays, read_polydata

    poly = read_polydata(path)
    points, point_arrays, cell_arrays = polydata_arrays(poly)
    cells = poly.GetLines()
    offsets = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64) if cells.GetNumberOfCells() else np.zeros(1, int)
    ids = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64) if cells.GetNumberOfCells() else np.zeros(0, int)
    lines = [ids[a:b].tolist() for a, b in zip(offsets[:-1], offsets[1:], strict=True)]
    return {"lines": lines, "points": points, "point": point_arrays, "cell": cell_arrays}


def _read_triangles(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and faces (F, 3) as the file stores them (trimesh, nothing merged or reordered)."""
    import trimesh

    mesh = trimesh.load(str(path), force="mesh", process=False)
    assert isinstance(mesh, trimesh.Trimesh), f"{path}: not one triangle mesh"
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


def _sizes(lines: list[list[int]]) -> list[int]:
    return [len(line) for line in lines]
