"""Mesh figures of a regression check: every mesh under ``meshes/`` by geometry, and golden.json allowances.

A reference's ``golden.json`` records what decimating each stored mesh lost
(:func:`decimation_entry`); :func:`mesh_figures` widens that mesh's
tolerances by it (see :mod:`softdesign.regression`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from softdesign.errors import InputDataError, SoftdesignError
from softdesign.io.formats import FORMATS, read_mesh
from softdesign.meshing.compare import MeshDifference, compare_meshes
from softdesign.pipeline.layout import MESHES_DIR
from softdesign.regression.figures import CheckOptions, Figure, is_number, missing_figure, read_json
from softdesign.types import FloatArray, IntArray

#: Every registered mesh format is compared by geometry.
MESH_SUFFIXES = tuple(f.suffix for f in FORMATS.values())
GOLDEN = "golden.json"


@dataclass(frozen=True)
class DecimationError:
    """What a golden reference lost by decimating one mesh (read from golden.json)."""

    distance_max_mm: float = 0.0
    volume_rel_change: float = 0.0
    area_rel_change: float = 0.0


def decimation_entry(difference: MeshDifference) -> dict[str, float]:
    """The golden.json record of one stored mesh: ``compare_meshes(stored, full_resolution)`` figures."""
    return {
        "distance_max_mm": difference.distance_max_mm,
        "volume_rel_change": difference.volume_rel_change,
        "area_rel_change": difference.area_rel_change,
    }


def read_golden(reference_dir: Path) -> dict[str, DecimationError]:
    """Per-mesh decimation errors from ``reference_dir/golden.json``; empty when there is none."""
    path = Path(reference_dir) / GOLDEN
    if not path.is_file():
        return {}
    meshes = read_json(path).get("meshes", {})
    if not isinstance(meshes, dict):
        raise InputDataError(f"{path}: 'meshes' must be an object of mesh path -> errors, got {type(meshes).__name__}")
    errors = {}
    for name, entry in meshes.items():
        values = {}
        for key in ("distance_max_mm", "volume_rel_change", "area_rel_change"):
            value = entry.get(key, 0.0) if isinstance(entry, dict) else None
            if not is_number(value) or not math.isfinite(value):
                raise InputDataError(f"{path}: meshes.{name}.{key} must be a finite number, got {value!r}")
            values[key] = abs(float(value))
        errors[name] = DecimationError(**values)
    return errors


def mesh_names(build_dir: Path) -> set[str]:
    """Mesh files under ``build_dir/meshes``, as paths relative to ``build_dir`` (``meshes/q_0.000.stl``)."""
    root = Path(build_dir) / MESHES_DIR
    if not root.is_dir():
        return set()
    found = (p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in MESH_SUFFIXES)
    return {p.relative_to(build_dir).as_posix() for p in found}


def compare_mesh_folders(
    build_dir: Path,
    reference_dir: Path,
    options: CheckOptions,
    golden: dict[str, DecimationError],
    progress: Callable[[str], None] | None = None,
) -> list[Figure]:
    """Figures of every mesh present on either side, sorted by name."""
    ours, theirs = mesh_names(build_dir), mesh_names(reference_dir)
    figures: list[Figure] = []
    for name in sorted(ours | theirs):
        if name not in ours or name not in theirs:
            figures.append(missing_figure(name, "mesh file", in_build=name in ours))
            continue
        if progress is not None:
            progress(f"check: comparing {name}")
        try:
            mesh, ref = read_mesh(build_dir / name), read_mesh(reference_dir / name)
            difference = compare_meshes(*mesh, *ref, samples=options.samples)
        except SoftdesignError as err:
            figures.append(Figure(name, "readable", None, None, False, note=str(err)))
            continue
        figures += mesh_figures(name, difference, options, golden.get(name, DecimationError()))
        figures += written_figures(name, *mesh)
    return figures


def written_figures(name: str, vertices: FloatArray, faces: IntArray) -> list[Figure]:
    """The build's mesh as a slicer reads it (float32, coincident vertices merged): its zero-area faces and
    non-manifold edges, each must be 0 (:func:`softdesign.meshing.checks.written_defects`)."""
    from softdesign.meshing.checks import written_defects

    zero, nonmanifold = written_defects(vertices, faces)
    note = "in the build, as written in single precision with coincident vertices merged; must be 0"
    return [Figure(name, key, float(value), 0.0, value == 0, build=value, note=note)
            for key, value in (("zero_area_faces", zero), ("nonmanifold_edges", nonmanifold))]


def mesh_figures(name: str, diff: MeshDifference, options: CheckOptions, allowance: DecimationError) -> list[Figure]:
    """The five figures of one mesh pair (four for open surfaces: no volume); tolerances widened by the
    reference's decimation error."""
    distance_tol = options.distance_mm + allowance.distance_max_mm
    note = "tolerance + golden.json decimation error" if allowance != DecimationError() else ""
    figures = [
        Figure(name, key, value, distance_tol, value <= distance_tol, note=note)
        for key, value in (("distance_max_mm", diff.distance_max_mm), ("distance_rms_mm", diff.distance_rms_mm))
    ]
    closed = diff.watertight and diff.reference_watertight  # an open surface (a region file) encloses nothing
    for key, value, extra in (
        ("volume_rel_change", diff.volume_rel_change, allowance.volume_rel_change),
        ("area_rel_change", diff.area_rel_change, allowance.area_rel_change),
    ):
        if key == "volume_rel_change" and not closed:
            continue
        tolerance = options.rtol + extra
        figures.append(Figure(name, key, value, tolerance, abs(value) <= tolerance, note=note))
    same = diff.watertight == diff.reference_watertight
    figures.append(Figure(name, "watertight", None, None, same, diff.watertight, diff.reference_watertight))
    return figures
