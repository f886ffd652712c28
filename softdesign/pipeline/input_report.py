"""``softdesign validate`` opens every input file: what it is, what it holds, and whether its size fits the units.

Each file a build reads (:func:`softdesign.pipeline.inputs.input_fields`) is
opened with the reader ingest uses: a centerline is read and its path chosen
(segments joined, as ingest joins them), a surface is read and triangulated.
The report gives each file's type, point and cell counts, data arrays and
extent in the case's units; the checks are the ones ingest makes first, so
validate refuses what a build would refuse at ingest, before any work:

* a surface mesh (STL, PLY, OBJ, glTF) given as a centerline;
* a centerline whose line cells join into no path (isolated 2-point segments);
* a vessel whose size is not human in the declared ``units`` (the message
  names the units that would fit), or a surface that does not surround the
  centerline (the message names the unit factor that would explain it).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softdesign.errors import InputDataError
from softdesign.types import UNIT_SCALE_TO_MM, FloatArray, IntArray

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.geometry.network import CenterlineNetwork, SelectedPath
    from softdesign.io.file_facts import FileFacts


def open_inputs(case: Case) -> list[str]:
    """Lines describing every input file of ``case``, after the checks ingest makes first.

    Raises
    ------
    InputDataError, ConfigError
        A file a build would refuse at ingest (see the module notes), with the reason and the fix.
    """
    from softdesign.pipeline.inputs import input_fields

    lines: list[str] = []
    if case.final.centerline == "auto":  # extracting takes seconds; init shows what it gives
        lines.append("final.centerline auto: extracted from final.surface at ingest; softdesign init SURFACE lists "
                     "its paths and proposes the main vessel")
    final: SelectedPath | None = None
    for key, path in input_fields(case):
        if key.endswith("centerline"):
            selected, described = _centerline(case, key, path)
            final = selected if key == "final.centerline" else final
        else:
            described = _surface(case, key, path, final if key == "final.surface" else None)
        lines += described
    return lines


def _centerline(case: Case, key: str, path: Path) -> tuple[SelectedPath, list[str]]:
    """Open a centerline file: its facts, the chosen path, the scale check."""
    from softdesign.geometry.network import Orientation, select_path
    from softdesign.geometry.plausibility import check_vessel_scale
    from softdesign.io.centerline import read_centerline_network
    from softdesign.io.file_facts import MESH_SUFFIXES, file_facts

    if path.suffix.lower() in MESH_SUFFIXES:
        raise InputDataError(_mesh_as_centerline(key, path, MESH_SUFFIXES[path.suffix.lower()]))
    facts = file_facts(path)
    scale = UNIT_SCALE_TO_MM[case.units]
    network = read_centerline_network(path, scale)
    index = _path_index(case, key)
    selected = select_path(network, index, Orientation())
    check_vessel_scale(selected.length, selected.radius, case.units, f"{key} {path.name}")
    points = np.concatenate([p.points for p in network.polylines])
    radius = "no radius in the file" + (" (ingest measures it on final.surface)" if case.final.surface else "")
    if selected.radius is not None:
        radius = f"radius {selected.radius.min():.3g} to {selected.radius.max():.3g} mm"
    return selected, [
        f"{key} {path.name}: {facts.text()}",
        f"  {len(network.polylines)} path(s); path {index}: {len(selected.points)} points, {selected.length:.2f} mm, "
        f"{radius}",
        f"  {_extent(points, case.units)}",
        *(f"  {note}" for note in network.notes),
        *(_paths_described(case, network, index) if key == "final.centerline" else []),
    ]


def _paths_described(case: Case, network: CenterlineNetwork, index: int) -> list[str]:
    """Every path in words, the main vessel by init's rule marked; whether ``final.path`` is it (issue 43)."""
    from softdesign.geometry.network import all_paths
    from softdesign.geometry.path_survey import MAIN_PATH_RULE, main_path, survey_paths
    from softdesign.pipeline.path_text import path_lines
    from softdesign.pipeline.surface_radius import with_surface_radius

    measured = with_surface_radius(case, network)  # as ingest measures a missing radius
    facts = survey_paths([(p.index, p.points, p.radius) for p in all_paths(measured)])
    main = main_path(facts)
    lines = [f"  {line}" for line in path_lines(facts, case.units, 1.0, main)]
    if len(facts) > 1:
        chosen = "is the main vessel" if index == main else f"is not the main vessel: path {main} is"
        lines.append(f"  final.path {index} {chosen} (by init's rule, {MAIN_PATH_RULE})")
    return lines


def _surface(case: Case, key: str, path: Path, final: SelectedPath | None) -> list[str]:
    """Open a surface file: its facts, its labels, the scale check against the centerline or alone."""
    from softdesign.geometry.plausibility import check_surface_surrounds, check_vessel_scale

    units = (case.final.surface_units if key == "final.surface" else None) or case.units
    # a missing radius is measured on the triangles (as ingest measures it); otherwise the corners suffice
    facts, vertices, faces = _surface_arrays(path, UNIT_SCALE_TO_MM[units],
                                             need_faces=final is not None and final.radius is None)
    if final is not None:  # as ingest checks it: a missing radius measured on this surface first
        radius = final.radius
        if radius is None:
            from softdesign.meshing.compare import squared_distances

            radius = np.sqrt(squared_distances(final.points, vertices, faces))
        check_surface_surrounds(final.points, radius, vertices, f"{key} {path.name}")
    elif key == "final.surface":  # centerline: auto: the surface alone says whether the units fit
        extent = float(np.ptp(vertices, axis=0).max())
        check_vessel_scale(extent, None, units, f"{key} {path.name} (its largest extent)")
    labels = ""
    if path.suffix.lower() in (".vtp", ".vtk"):
        from softdesign.io.centerline_vtp import read_face_regions

        regions = read_face_regions(path)
        labels = "" if regions is None else f"; {len(np.unique(regions))} face labels"
    return [f"{key} {path.name}: {facts.text()}{labels}", f"  {_extent(vertices, units)}"]


def _surface_arrays(path: Path, scale_to_mm: float, need_faces: bool) -> tuple[FileFacts, FloatArray, IntArray]:
    """The file's facts, vertices (V, 3) mm and faces (F, 3) (empty unless ``need_faces``) of a surface.

    A binary STL is read with numpy alone (:mod:`softdesign.io.stl_corners`: its distinct corners are the
    vertices the build's reader merges them into); other files with the build's readers (trimesh, vtk).
    """
    from softdesign.io.file_facts import FileFacts, file_facts
    from softdesign.io.surface import check_surface_arrays, read_surface

    if path.suffix.lower() == ".stl" and not need_faces:
        from softdesign.io.stl_corners import binary_stl_corners

        corners = binary_stl_corners(path)
        if corners is not None:
            vertices, triangles = corners
            check_surface_arrays(path, vertices, triangles)
            no_faces = np.zeros((0, 3), dtype=np.int64)
            return FileFacts("STL", len(vertices), {"triangles": triangles}), vertices * scale_to_mm, no_faces
    facts = file_facts(path)
    vertices, faces = read_surface(path, scale_to_mm)
    return facts, vertices, faces


def _path_index(case: Case, key: str) -> int:
    if key == "final.centerline":
        return int(case.final.path)
    if key == "initial.centerline":
        return int(case.initial.path)
    return int(case.intermediate[int(key.split("[")[1].split("]")[0])].path)


def _extent(points_mm: np.ndarray, units: str) -> str:
    """``extent 24.1 x 80.2 x 20.1 mm (in units: mm)``"""
    size = np.ptp(points_mm, axis=0) / UNIT_SCALE_TO_MM[units]
    return f"extent {size[0]:.4g} x {size[1]:.4g} x {size[2]:.4g} {units} (units: {units})"


def _mesh_as_centerline(key: str, path: Path, kind: str) -> str:
    fix = (
        "give it as final.surface and set final.centerline: auto (the centerline is then extracted from it)"
        if key == "final.centerline" else
        f"compute its centerline first (softdesign centerline {path} --output {path.with_suffix('.vtp').name}) "
        f"and give that file as {key}"
    )
    return (f"{key}: {path} is a surface mesh ({kind}), not a centerline; expected VMTK centerlines (.vtp, .vtk, "
            f".vtu, .csv or .npy): {fix}")
