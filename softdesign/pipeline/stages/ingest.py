"""Stage 1, ingest: read the case's centerlines and surfaces, select the path, check them.

Everything is converted to millimetres here.  The result is kept in the
build folder under ``ingest/`` so later stages never re-read the inputs.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.geometry.edges import EdgeTable
from softdesign.geometry.end_planes import flat_labels
from softdesign.geometry.network import CenterlineNetwork, Orientation, SelectedPath, all_paths, select_path
from softdesign.geometry.plausibility import check_surface_surrounds, check_vessel_scale
from softdesign.io.centerline import read_centerline_network
from softdesign.io.surface import read_surface
from softdesign.meshing.topology import SurfaceInfo, describe_surface
from softdesign.pipeline import layout
from softdesign.pipeline.auto_centerline import (
    continuation_note,
    extract_for_case,
    extraction_summary,
    write_extracted,
)
from softdesign.pipeline.backbone_step import regularized_path
from softdesign.pipeline.end_plane_step import end_plane_summary
from softdesign.pipeline.item_progress import step_counter
from softdesign.pipeline.notices import NOTE, Notice
from softdesign.pipeline.parallel import map_items
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.store import Staging, load_npz, npz_bytes
from softdesign.pipeline.surface_radius import with_surface_radius
from softdesign.types import UNIT_SCALE_TO_MM, FloatArray

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

#: 2: a vessel whose size is not human in the declared units is refused (it was a warning on radii only).
#: 3: a final path that turns tighter than the vessel is wide is regularized here (``backbone``); reads resample;
#: the rule that chose the inlet (``centerline.inlet_rule``: the clearly widest end first).
#: 4: each end's flat cap or open loop, its tilt to the end tangent and the rim's gap past the body (``end_planes``).
#: 5: the rim-gap warning moved to the fit, which decides whether the body is cut at the plane (``fit.end_cut``).
#: 6: a centerline without radii takes them from final.surface; 2-point segments and unstructured grids are
#: joined into paths; extracted centerlines reach the openings (issue 29).
#: 7: the backbone's reach uses the wall's fold radius; a turn no smoothing brings below the target is warned
#: about, not refused (issue 29).
VERSION = 8  # 8: lengths in the notes in the case's unit (mm beside), wall face labels said once
#: The steps the ingest tells a terminal as it goes (:func:`~softdesign.pipeline.item_progress.step_counter`).
INGEST_STEPS = ("centerline", "surface", "backbone", "end planes", "summary")


@dataclass(frozen=True)
class IngestResult:
    """What ingest found, in mm.

    Attributes
    ----------
    path : the selected final path, inlet first
    others : every other path of the network, inlet first (for branch exclusion)
    vertices, faces : the final surface, or empty arrays when none was given
    initial_path : the q = 0 centerline when ``initial.kind: file``
    keyframes : (q, path) of each intermediate shape
    initial_surface : (vertices, faces) of ``initial.surface``, or None
    summary : the JSON-ready report printed and stored
    notes : what was done on the way (duplicates, orientation, warnings)
    extracted : the centerline extracted from the surface (``final.centerline: auto``), or None
    """

    path: SelectedPath
    others: tuple[SelectedPath, ...]
    vertices: FloatArray
    faces: np.ndarray
    initial_path: SelectedPath | None = None
    keyframes: tuple[tuple[float, SelectedPath], ...] = ()
    initial_surface: tuple[FloatArray, np.ndarray] | None = None
    summary: dict[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    extracted: Any = None


def run_ingest(case: Case) -> IngestResult:
    """Read and check every input of ``case``.

    Raises
    ------
    InputDataError
        A file is missing, unreadable or geometrically unusable.
    ConfigError
        The vessel's size is not a human vessel's in the declared ``units`` (checked before the surface is read).
    """
    scale = UNIT_SCALE_TO_MM[case.units]
    step = step_counter("ingest", INGEST_STEPS)  # a bar on a terminal: a tree's steps take seconds each
    network, extracted, radius_from = _final_network(case, scale)
    inlet = None if case.final.inlet is None else np.asarray(case.final.inlet, float) * scale
    orientation = Orientation(inlet=inlet, reverse=case.final.reverse)
    path = select_path(network, case.final.path, orientation)
    check_vessel_scale(path.length, path.radius, case.units, f"final.centerline {_centerline_name(case)}")
    every = all_paths(network, Orientation(inlet=path.points[0]))  # once: a tree has hundreds
    others = tuple(p for p in every if p.index != path.index)
    step("centerline")
    notes = list(network.notes) + list(path.notes)
    if extracted is not None:
        notes += [*extracted.notes, continuation_note(extracted, case.units)]
    inlet_rule = path.notes[-1]
    surface = _final_surface(case, path, scale, others)
    vertices, faces, info = surface.vertices, surface.faces, surface.info
    step("surface")
    path, backbone = surface.path, surface.backbone
    notes += [n for n in path.notes if n not in notes]
    step("backbone")
    ends = end_plane_summary(case, path, vertices, faces, surface.edges, surface.flat)
    step("end planes")
    initial_path = None
    if case.initial.kind == "file" and case.initial.centerline is not None:
        initial_path = _one_path(case.initial.centerline, case.initial.path, scale, Orientation())
        notes += initial_path.notes
    keyframes = tuple(
        (k.q, _one_path(k.centerline, k.path, scale, Orientation(inlet=path.points[0], reverse=k.reverse)))
        for k in case.intermediate
    )
    initial_surface = None
    if case.initial.surface is not None:
        initial_surface = read_surface(case.initial.surface, scale)
    summary = {**_summary(case, network, every, path, info), "backbone": backbone, "end_planes": ends}
    step("summary")
    summary["centerline"]["inlet_rule"] = inlet_rule
    summary["centerline"]["radius_from"] = radius_from if path.radius is not None else None
    if extracted is not None:
        summary["centerline"]["extracted"] = extraction_summary(extracted)
    return IngestResult(
        path, others, vertices, faces, initial_path, keyframes, initial_surface, summary, tuple(notes), extracted
    )


def _final_network(case: Case, scale: float) -> tuple[CenterlineNetwork, Any, str]:
    """The final centerline network (mm), read, or extracted from the surface (then also the extraction), and
    where its radii come from."""
    if case.final.centerline == "auto":
        return *extract_for_case(case), "the extraction (distance to final.surface)"
    read = read_centerline_network(case.final.centerline, scale)
    network = with_surface_radius(case, read)
    return network, None, "MaximumInscribedSphereRadius" if network is read else "distance to final.surface"


def _centerline_name(case: Case) -> str:
    centerline = case.final.centerline
    return "auto" if centerline == "auto" else Path(centerline).name


def _one_path(file: Path, index: int, scale: float, orientation: Orientation) -> SelectedPath:
    return select_path(read_centerline_network(file, scale), index, orientation)


@dataclass(frozen=True)
class _Surface:
    """The final surface (mm) and what the ingest finds on it beside the path."""

    vertices: FloatArray
    faces: np.ndarray
    info: SurfaceInfo | None
    edges: EdgeTable | None  # one sort of its edges, which the end planes read too
    flat: np.ndarray | None  # its flat regions (the end planes'), or None
    path: SelectedPath  # the path, regularized (:func:`~softdesign.pipeline.backbone_step.regularized_path`)
    backbone: dict[str, Any] | None


def _final_surface(case: Case, path: SelectedPath, scale: float, others: tuple[SelectedPath, ...]) -> _Surface:
    """The final surface (mm), its description, edge table and flat regions, and the regularized path.

    Two tasks on the build's workers, each the build process's serial work before: the surface's flat regions
    (:func:`~softdesign.geometry.end_planes.flat_labels`, the path-free third of the end planes), and the check
    that the surface surrounds the path, its description and the path regularized against it (an error of
    theirs is raised here as before).  The same numbers in either process.
    """
    if case.final.surface is None:
        vertices = np.zeros((0, 3))
        regular, backbone = regularized_path(case, path, vertices, others)
        return _Surface(vertices, np.zeros((0, 3), np.int64), None, None, None, regular, backbone)
    surface_scale = UNIT_SCALE_TO_MM[case.final.surface_units] if case.final.surface_units else scale
    vertices, faces = read_surface(case.final.surface, surface_scale, map_items)  # a big STL's merge on the workers
    edges = EdgeTable.of(np.asarray(faces, np.int64), len(vertices))

    def task(which: int) -> Any:
        if which == 0:  # the end planes measure nothing without inscribed radii
            return None if path.radius is None else flat_labels(vertices, faces, edges)
        check_surface_surrounds(path.points, path.radius, vertices, str(case.final.surface))
        return describe_surface(vertices, faces, edges), regularized_path(case, path, vertices, others)

    flat, (info, (regular, backbone)) = map_items(task, [0, 1])
    return _Surface(vertices, faces, info, edges, flat, regular, backbone)


def _summary(case: Case, network: CenterlineNetwork, every: list[SelectedPath], path: SelectedPath,
             info: SurfaceInfo | None) -> dict[str, Any]:
    paths = [{"path": p.index, "points": int(len(p.points)), "length_mm": round(p.length, 6)} for p in every]
    radius = None if path.radius is None else [float(path.radius.min()), float(path.radius.max())]
    return {
        "units": case.units,
        "centerline": {
            "file": _centerline_name(case),
            "branch_split": network.branch_split,
            "polylines": len(network.polylines),
            "paths": paths,
            "selected": path.index,
            "selected_points": int(len(path.points)),
            "selected_length_mm": path.length,
            "radius_range_mm": radius,
            "inlet_mm": path.points[0].tolist(),
            "outlet_mm": path.points[-1].tolist(),
            "bounds_mm": [path.points.min(axis=0).tolist(), path.points.max(axis=0).tolist()],
        },
        "surface": None if info is None or case.final.surface is None else {
            "file": case.final.surface.name, **info.as_dict()
        },
    }


def write_ingest(result: IngestResult, staging: Staging) -> None:
    """Keep the ingest result in the build folder (``ingest/``)."""
    staging.write_bytes(layout.INGEST_PATH, _path_npz(result.path))
    others = {f"path_{p.index}": p.points for p in result.others}
    staging.write_bytes(layout.INGEST_NETWORK, npz_bytes(**others))
    staging.write_bytes(layout.INGEST_SURFACE, npz_bytes(vertices=result.vertices, faces=result.faces))
    if result.initial_path is not None:
        staging.write_bytes(layout.INGEST_INITIAL_PATH, _path_npz(result.initial_path))
    for k, (q, keyframe) in enumerate(result.keyframes):
        staging.write_bytes(layout.ingest_keyframe(k), _path_npz(keyframe, q=np.array(q)))
    if result.initial_surface is not None:
        v, f = result.initial_surface
        staging.write_bytes(layout.INGEST_INITIAL_SURFACE, npz_bytes(vertices=v, faces=f))
    if result.extracted is not None:
        write_extracted(result.extracted, staging, result.summary["units"])
    staging.write_json(layout.INGEST_SUMMARY, {**result.summary, "notes": list(result.notes)})


def _path_npz(path: SelectedPath, **extra: np.ndarray) -> bytes:
    arrays = {"points": path.points, "index": np.array(path.index), **extra}
    if path.radius is not None:
        arrays["radius"] = path.radius
    return npz_bytes(**arrays)


def load_ingest(build_dir: Path) -> IngestResult:
    """Re-read the ingest result kept in ``build_dir/ingest``."""
    root = Path(build_dir)
    path = _load_path(root / layout.INGEST_PATH)
    network = load_npz(root / layout.INGEST_NETWORK)
    others = tuple(
        SelectedPath(v, None, int(k.removeprefix("path_"))) for k, v in sorted(network.items())
    )
    surface = load_npz(root / layout.INGEST_SURFACE)
    initial_file = root / layout.INGEST_INITIAL_PATH
    initial = _load_path(initial_file) if initial_file.is_file() else None
    keyframes = tuple(
        (float(load_npz(f)["q"]), _load_path(f))
        for f in sorted(root.glob(layout.ingest_keyframe("*")), key=lambda f: int(f.stem.removeprefix("keyframe_")))
    )
    initial_surface = None
    if (root / layout.INGEST_INITIAL_SURFACE).is_file():
        data = load_npz(root / layout.INGEST_INITIAL_SURFACE)
        initial_surface = (data["vertices"], data["faces"])
    summary = json.loads((root / layout.INGEST_SUMMARY).read_text(encoding="utf-8"))
    notes = tuple(summary.pop("notes", ()))
    return IngestResult(
        path, others, surface["vertices"], surface["faces"], initial, keyframes, initial_surface, summary, notes
    )


def _load_path(file: Path) -> SelectedPath:
    data = load_npz(file)
    return SelectedPath(data["points"], data.get("radius"), int(data["index"]))


def describe_ingest(result: IngestResult) -> list[str]:
    """The network's paths (the selected one starred), the surface, the units and the notes."""
    c = result.summary["centerline"]
    lines = [f"centerline {c['file']}: {c['polylines']} polyline(s), branch-split: {c['branch_split']}"]
    for p in c["paths"]:
        mark = "*" if p["path"] == c["selected"] else " "
        lines.append(f" {mark} path {p['path']}: {p['points']} points, {p['length_mm']:.2f} mm")
    if c["radius_range_mm"]:
        lo, hi = c["radius_range_mm"]
        lines.append(f"   radius {lo:.3f} .. {hi:.3f} mm ({c.get('radius_from') or 'MaximumInscribedSphereRadius'})")
    s = result.summary["surface"]
    if s:
        kind = "capped (watertight)" if s["capped"] else f"open, {s['boundary_loops']} boundary loop(s)"
        lines.append(f"surface {s['file']}: {s['vertices']} vertices, {s['faces']} triangles, {kind}")
    lines.append(f"units: {result.summary['units']} (converted to mm)")
    return lines  # the notes are :func:`ingest_notices`': printed once from the manifest


def ingest_notices(result: IngestResult) -> list[Notice]:
    """The notes of what was done on the way (duplicates, orientation), and its warnings (``warning: ...`` notes:
    a centerline that turns tighter than the vessel is wide, an end the extraction could not place)."""
    notices = []
    for text in result.notes:
        if text.startswith("warning: "):
            body = text.removeprefix("warning: ")
            code = "tight_turn" if "turns" in body and "than the vessel is wide" in body else "centerline"
            notices.append(Notice("ingest", code, "", body))
        else:
            notices.append(Notice("ingest", "note", "", text, NOTE))
    return notices


STAGE = Stage(
    name="ingest",
    version=VERSION,
    reads=(
        "units", "final", "resample", "initial.kind", "initial.centerline", "initial.path", "initial.surface",
        "intermediate",
    ),
    upstream=(),
    compute=lambda case, results: run_ingest(case),
    write=write_ingest,
    load=lambda build_dir, results: load_ingest(build_dir),
    describe=describe_ingest,
    metrics=lambda result: result.summary,
    warnings=ingest_notices,
)
