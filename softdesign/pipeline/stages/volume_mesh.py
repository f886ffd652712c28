"""Stage, volume_mesh: tetrahedral meshes of the body for simulators (SOFA, FEBio, Abaqus), issues 16 and 32.

Runs only when the case has ``export.volume_mesh``; otherwise it writes
nothing.  ``mesher: sweep`` (the default, issue 32) is
:mod:`softdesign.pipeline.stages.volume_sweep`: one mesh of the body's
parameter domain placed at every q (the same connectivity, deterministic
bytes), its surfaces named in the files (skin, base, tip, the chamber's
wall and caps, the port's wall; the base's nodes), the 3D strain and stress
per element in the figures.  ``mesher: ftetwild`` is issue 16's, below.
At each of its q values (by default q = 0 alone, the state the
actuator is cast in and that a simulator deforms) the body is the export's
own checked solid (same grid, offset, wall and port), and fTetWild fills it
with tetrahedra of the target size (:mod:`softdesign.meshing.volume_mesh.tetmesh`) in a
child process with the case's time limit (:mod:`softdesign.pipeline.child`):
a crash or a hang in its native code fails the stage with a clear message
(exit 1), not a dead build.  The count of tetrahedra the size asks for is
bounded before the mesher starts.  Checks (:mod:`softdesign.meshing.volume_mesh.tet_checks`):
every tetrahedron positive, their volume within 1 % of the body's, a hollow
body's chamber empty.  Outputs: ``meshes/volume/q_0.000.vtu`` (ASCII XML,
inline data: what SOFA's MeshVTKLoader reads), ``.msh`` (Gmsh 2.2, SOFA's
MeshGmshLoader), for a hollow body ``meshes/volume/chamber_q_0.000.stl`` (the
closed chamber, normals outwards: SOFA's SurfacePressureConstraint), and
``volume/summary.json``; the manifest lists each file with its figures.

fTetWild is not deterministic (:mod:`softdesign.meshing.volume_mesh.tetmesh`): unlike
every other output, these files differ from run to run of the mesher (their
figures agree within the checks).  The build's cache keeps them while the
inputs are unchanged.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, replace
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.config import Case
from softdesign.config import VolumeMesh as VolumeMeshSpec
from softdesign.errors import ConfigError
from softdesign.io.formats import mesh_bytes
from softdesign.io.volume_formats import VOLUME_FORMATS, NamedSets, volume_mesh_bytes
from softdesign.limits.volume import MAX_VOLUME_TETS, MESHER_MEMORY_BYTES
from softdesign.meshing.body.sections import body_sections
from softdesign.meshing.chambers.surface import chamber_surface
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.tet_checks import REGULAR_TET_FACTOR, check_tet_mesh, expected_tets
from softdesign.meshing.volume_mesh.tetmesh import TetSettings, tetrahedralize
from softdesign.pipeline import layout
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.child import run_in_child
from softdesign.pipeline.output_frame import base_pose, moved_points, output_pose
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.export import solid_at
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.judges import material_judgement
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.pipeline.store import Staging
from softdesign.types import FloatArray, IntArray

VERSION = 7  # 3: export.frame (the meshes in the patient's or the base frame); 4: VTK's .vtu, no times in the summary;
# 5: the swept section's GROWTH 1.4, sections and chambers named from 1, a solid body's end layers at its crease;
# 6: the .vtu names its surface codes in field data; 7: a three-fold symmetric chambered section meshed symmetric
#: The function the child process runs: (vertices, faces, TetSettings) -> (points, tets).  A module attribute,
#: so that a test can put a crashing or hanging stand-in in its place.
MESHER = tetrahedralize


@dataclass(frozen=True)
class TetBody:
    """The tetrahedra of the body at one q, and its closed chamber (hollow bodies), and named sets (sweep)."""

    q: float
    points: FloatArray
    tets: IntArray
    chamber: tuple[FloatArray, IntArray] | None
    sets: NamedSets | None = None
    #: every cavity's closed surface by name (sweep: ``chamber``, or ``s1_c1`` ... with their feeds)
    cavities: dict[str, tuple[FloatArray, IntArray]] | None = None


@dataclass(frozen=True)
class VolumeMeshResult:
    """The meshes (empty after a cached load, or when none is asked for) and the figures."""

    meshes: tuple[TetBody, ...]
    summary: dict[str, Any]
    #: a line per part with its time: printed with the stage's description and kept in the build folder's run log
    #: (run.log.json), never in an output, which depends on the inputs alone (issue 35)
    log: tuple[str, ...] = ()


def _check_count(volume_mm3: float, size_mm: float, q: float) -> None:
    count = expected_tets(volume_mm3, size_mm)
    if count > MAX_VOLUME_TETS:
        least = (volume_mm3 * REGULAR_TET_FACTOR / MAX_VOLUME_TETS) ** (1.0 / 3.0)
        raise ConfigError(
            f"export.volume_mesh.size_mm: {size_mm:g} mm asks for about {count:.3g} tetrahedra in the body's "
            f"{volume_mm3:.1f} mm3 at q={q:.3f}, more than the limit of {MAX_VOLUME_TETS} "
            f"(softdesign/limits/volume.py); use size_mm >= {np.ceil(least * 1000) / 1000:g} mm"
        )


def mesh_body(case: Case, kinematics: KinematicsResult, fit: FitResult,
              q: float) -> tuple[TetBody, dict[str, Any], float]:
    """The checked tetrahedral mesh of the body at ``q``, its figures (MeshError when a check fails) and the
    mesher's seconds."""
    vm = case.export.volume_mesh or VolumeMeshSpec()
    body = solid_at(kinematics, fit, q, case)
    volume = float(body.figures["volume_mm3"])
    _check_count(volume, vm.size_mm, q)
    spec = body_spec(case, fit)
    chamber = None
    if spec.wall_mm > 0:
        e = case.export
        sections = body_sections(kinematics.chain.shape.curve_at(q), fit.field, q, e.spacing_mm, e.angular_count)
        chamber = chamber_surface(sections, spec)
    what = f"fTetWild on the body at q={q:.3f} ({len(body.solid.faces)} faces, size_mm {vm.size_mm:g})"
    fix = ("raise export.volume_mesh.timeout_s, or make the mesh coarser (size_mm, envelope_mm); a crash in fTetWild "
           f"is a bug to report with the body (`softdesign export` writes it: {layout.mesh_path(q, 'stl')})")
    start = time.perf_counter()
    points, tets = run_in_child(MESHER, (body.solid.vertices, body.solid.faces,
                                         TetSettings(vm.size_mm, vm.envelope_mm)), vm.timeout_s, what, fix,
                                  memory_bytes=MESHER_MEMORY_BYTES)
    seconds = time.perf_counter() - start
    figures = check_tet_mesh(points, tets, volume, chamber, f"volume mesh at q={q:.3f}")
    figures.update({"q": q, "size_mm": vm.size_mm, "envelope_mm": vm.envelope_mm, "body_kind": body.solid.kind})
    return TetBody(q, points, tets, chamber), figures, seconds


def _chamber_figures(q: float, chamber: tuple[FloatArray, IntArray]) -> dict[str, Any]:
    topology = mesh_topology(*chamber)
    return {"q": q, "part": "chamber", "faces": topology.faces, "volume_mm3": topology.volume,
            "area_mm2": topology.area, "watertight": topology.watertight,
            "winding_consistent": topology.winding_consistent,
            "normals": "outward" if topology.volume > 0 else "inward"}


def run_volume_mesh(case: Case, kinematics: KinematicsResult, fit: FitResult) -> VolumeMeshResult:
    """A checked tetrahedral mesh at every q of ``export.volume_mesh``, or nothing when the case asks for none."""
    vm = case.export.volume_mesh
    if vm is None:
        return VolumeMeshResult((), {"requested": False})
    pose = output_pose(case.export.frame, base_pose(kinematics.chain.shape))  # checked first, then moved rigidly
    if vm.mesher == "sweep":
        swept = _run_sweep(case, kinematics, fit)
        return VolumeMeshResult(tuple(_moved(m, pose) for m in swept.meshes), {**swept.summary,
                                                                               "output_frame": case.export.frame},
                                swept.log)
    meshes, files, per_q, log = [], {}, [], []
    for q in vm.q:
        mesh, figures, seconds = mesh_body(case, kinematics, fit, q)
        log.append(f"q={q:.3f}: fTetWild {seconds:.1f} s")
        meshes.append(mesh)
        per_q.append(figures)
        for suffix in VOLUME_FORMATS:
            files[layout.volume_mesh_path(q, suffix)] = figures
        if mesh.chamber is not None:
            files[layout.chamber_surface_path(q)] = _chamber_figures(q, mesh.chamber)
    mesher = {"name": "fTetWild through pytetwild, one thread", "pytetwild": metadata.version("pytetwild"),
              "meshio": metadata.version("meshio")}
    summary = {"requested": True, "spec": vm.model_dump(mode="json"), "mesher": mesher,
               "deterministic": False, "per_q": per_q, "files": files, "output_frame": case.export.frame}
    return VolumeMeshResult(tuple(_moved(m, pose) for m in meshes), summary, tuple(log))


def _run_sweep(case: Case, kinematics: KinematicsResult, fit: FitResult) -> VolumeMeshResult:
    """The swept mesher's meshes, files and figures (:mod:`softdesign.pipeline.stages.volume_sweep`)."""
    from softdesign.pipeline.stages.volume_sweep import material_of, part_lines, run_sweep

    vm = case.export.volume_mesh or VolumeMeshSpec()
    run = run_sweep(case, kinematics, fit)
    meshes, files = [], {}
    for body, figures in zip(run.bodies, run.per_q, strict=True):
        mesh = body.mesh
        surfaces = {name: mesh.group_faces(name) for name in mesh.groups} | dict(mesh.lids)
        sets = NamedSets(surfaces, {"base_nodes": mesh.base_nodes()}, body.tet_data)
        cavities = {c: (body.points, mesh.cavity_surface(c)) for c in dict.fromkeys(h.cavity_name for h in mesh.holes)}
        meshes.append(TetBody(body.q, body.points, mesh.tets, cavities.get("chamber"), sets, cavities))
        for suffix in VOLUME_FORMATS:
            files[layout.volume_mesh_path(body.q, suffix)] = figures
        for name, cavity in cavities.items():
            files[layout.cavity_surface_path(body.q, name)] = _chamber_figures(body.q, cavity)
    material = material_of(case)
    judged = material.max_stretch is not None or material.tensile_strength_kpa is not None
    first = run.bodies[0].mesh
    summary = {"requested": True, "spec": vm.model_dump(mode="json"),
               "mesher": {"name": "sweep: softdesign.meshing.volume_mesh.sweep_mesh, one mesh of the parameter domain",
                          "meshio": metadata.version("meshio")},
               "deterministic": True, "surfaces": list(first.groups) + list(first.lids),
               "node_sets": ["base_nodes"], "per_q": run.per_q, "morph": run.morph,
               "material": {"name": material.name, "max_stretch": material.max_stretch,
                            "tensile_strength_kpa": material.tensile_strength_kpa,
                            "law": None if material.law is None else material.law.kind},
               "feasible": (not run.reasons) if judged else None, "reasons": run.reasons, "files": files}
    return VolumeMeshResult(tuple(meshes), summary, tuple(part_lines(run.parts)))


def _moved(mesh: TetBody, pose: np.ndarray | None) -> TetBody:
    """The mesh, its chamber and its cavities in the output frame (``export.frame``; None: as it is)."""
    if pose is None:
        return mesh
    chamber = None if mesh.chamber is None else (moved_points(mesh.chamber[0], pose), mesh.chamber[1])
    cavities = None if mesh.cavities is None else {
        name: (moved_points(points, pose), faces) for name, (points, faces) in mesh.cavities.items()}
    return replace(mesh, points=moved_points(mesh.points, pose), chamber=chamber, cavities=cavities)


def write_volume_mesh(result: VolumeMeshResult, staging: Staging) -> None:
    """Stage every mesh in .vtu and .msh, every chamber as STL, and the figures."""
    if not result.summary["requested"]:
        return
    memo: dict[str, str] = {}  # the swept mesh's .msh elements, the same at every q, are formatted once
    for mesh in result.meshes:
        for suffix in VOLUME_FORMATS:
            data = volume_mesh_bytes(mesh.points, mesh.tets, suffix, mesh.sets, memo)
            staging.write_bytes(layout.volume_mesh_path(mesh.q, suffix), data)
        if mesh.cavities is not None:
            for name, (points, faces) in mesh.cavities.items():  # only the cavity's own nodes, not every node
                used, local = np.unique(faces, return_inverse=True)
                staging.write_bytes(layout.cavity_surface_path(mesh.q, name),
                                    mesh_bytes(points[used], local.reshape(-1, 3), "stl"))
        elif mesh.chamber is not None:
            staging.write_bytes(layout.chamber_surface_path(mesh.q), mesh_bytes(*mesh.chamber, "stl"))
    staging.write_json(layout.VOLUME_SUMMARY, result.summary)


def load_volume_mesh(build_dir: Path) -> VolumeMeshResult:
    """The figures of kept volume meshes (the files stay on disk)."""
    path = Path(build_dir) / layout.VOLUME_SUMMARY
    if not path.is_file():
        return VolumeMeshResult((), {"requested": False})
    return VolumeMeshResult((), json.loads(path.read_text(encoding="utf-8")))


def describe_volume_mesh(result: VolumeMeshResult) -> list[str]:
    """A line per part with its time (when computed in this run), then per tetrahedral mesh and chamber surface."""
    s = result.summary
    if not s["requested"]:
        return ["no export.volume_mesh in the case file: no volume mesh"]
    if s.get("deterministic"):
        from softdesign.pipeline.stages.volume_sweep import describe_sweep

        return [*result.log, *describe_sweep(s)]
    lines = list(result.log)
    for name, f in s["files"].items():
        if name.endswith(".msh"):
            continue
        if f.get("part") == "chamber":
            lines.append(f"{name}: closed chamber, {f['faces']} faces, {f['volume_mm3']:.2f} mm3, "
                         f"normals {f['normals']}")
            continue
        inside = f.get("chamber_centroids_inside")  # fTetWild's meshes only
        chamber = "" if inside is None else f", {inside} in the chamber"
        lines.append(
            f"{name} (and .msh): {f['tets']} tets, volume {f['volume_mm3']:.2f} mm3 "
            f"({100 * f['volume_rel_error']:+.3f}% vs body){chamber}, min dihedral {f['min_dihedral_deg']:.2f} deg, "
            f"max radius-edge {f['max_radius_edge']:.2f}")
    return lines


STAGE = Stage(
    name="volume_mesh",
    version=VERSION,
    # actuation: the solid it meshes has the chambers
    reads=("export.volume_mesh", "export.offset_mm", "export.wall_mm", "export.port_mm", "export.spacing_mm",
           "export.angular_count", "export.frame", "actuation", "material"),
    upstream=("kinematics", "fit"),
    compute=lambda case, results: run_volume_mesh(case, results["kinematics"], results["fit"]),
    write=write_volume_mesh,
    load=lambda build_dir, results: load_volume_mesh(build_dir),
    describe=describe_volume_mesh,
    metrics=lambda result: {k: v for k, v in result.summary.items() if k != "files"},
    figures=lambda result: result.summary["files"] if result.summary["requested"] else {},
    log=lambda result: list(result.log),
    judge=lambda result: material_judgement(result.summary if result.summary["requested"] else None, "3D"),
)
