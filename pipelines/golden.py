"""Store golden references of a built cohort (run by `make golden`, nowhere else).

    golden.py --cohort configs/cohort --build build/golden-cohort --out tests/golden

For every case file COHORT/<case>.yaml, built into BUILD/<case>/, this
writes OUT/<case>/ as a reference folder for ``softdesign check``:

- ``manifest.json`` and ``kinematics.json`` as the build wrote them;
- every mesh under ``meshes/``, decimated (vtk's quadric decimation, the
  strongest reduction that keeps the stored mesh watertight and within
  ``--max-error-mm`` of the full-resolution one), so the references stay small;
- ``golden.json``: each stored mesh's own error against the full mesh
  (``distance_max_mm``, ``volume_rel_change``, ``area_rel_change``, as
  :func:`softdesign.regression.decimation_entry` gives them; ``check`` widens
  that mesh's tolerances by them), the case file's path and sha256, the input
  files' sha256, and the versions of the software that made the build
  (:func:`softdesign.pipeline.versions.software_versions`, as the manifest records them).

The new references are written beside OUT and swapped in only when every
case succeeded, so a failed run leaves the old references as they were.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

from softdesign.cohort import STATUS_SUFFIX, cohort_cases, read_record
from softdesign.io.formats import read_mesh, write_mesh
from softdesign.meshing.compare import MeshDifference, compare_meshes
from softdesign.meshing.topology import is_winding_consistent
from softdesign.pipeline.layout import MANIFEST
from softdesign.pipeline.store import sha256_file
from softdesign.pipeline.versions import software_versions
from softdesign.regression import GOLDEN, KINEMATICS, decimation_entry, mesh_names

#: Strongest target reduction tried, and how many bisection steps find the strongest acceptable one.
MAX_REDUCTION, BISECTIONS = 0.97, 6
#: Largest distance a stored mesh may be from the full one, mm (check widens its tolerance by the actual error).
MAX_ERROR_MM = 0.05
DECIMATION = (
    "vtkQuadricDecimation (volume preservation on), the strongest reduction <= {} "
    "keeping the mesh watertight within {} mm"
)


def decimate(vertices: np.ndarray, faces: np.ndarray, reduction: float) -> tuple[np.ndarray, np.ndarray]:
    """The mesh with about ``reduction`` of its faces removed by quadric error decimation."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkQuadricDecimation

    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    if reduction <= 0.0:
        return vertices, faces
    poly = polydata_from_triangles(vertices, faces)
    decimation = vtkQuadricDecimation()
    decimation.SetInputData(poly)
    decimation.SetTargetReduction(reduction)
    decimation.VolumePreservationOn()
    decimation.Update()
    out = decimation.GetOutput()
    kept = vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
    return kept, vtk_to_numpy(out.GetPolys().GetConnectivityArray()).astype(np.int64).reshape(-1, 3)


def store_mesh(source: Path, target: Path, max_error_mm: float) -> tuple[MeshDifference, int, int]:
    """Write the most decimated acceptable version of ``source`` to ``target``.

    The reduction is bisected between 0 (the full mesh, always acceptable)
    and MAX_REDUCTION.  Returns the stored mesh's difference from the full one
    (as read back from ``target``, float32 STL included), and the face counts
    before and after.
    """
    full = read_mesh(source)

    def attempt(reduction: float) -> MeshDifference | None:
        write_mesh(target, *decimate(*full, reduction))
        stored = read_mesh(target)
        difference = compare_meshes(*stored, *full)
        closed_alike = is_winding_consistent(stored[1]) == is_winding_consistent(full[1])
        ok = closed_alike and difference.distance_max_mm <= max_error_mm
        return difference if ok else None

    good, bad = 0.0, MAX_REDUCTION
    if attempt(bad) is not None:
        good = bad
    else:
        for _ in range(BISECTIONS):
            middle = 0.5 * (good + bad)
            good, bad = (middle, bad) if attempt(middle) is not None else (good, middle)
    difference = attempt(good)
    if difference is None:
        raise RuntimeError(f"{source}: the stored mesh does not read back watertight within {max_error_mm} mm")
    return difference, len(full[1]), len(read_mesh(target)[1])


def store_case(case_file: Path, build_dir: Path, out_dir: Path, max_error_mm: float) -> dict:
    """Write one case's reference folder; returns its golden.json payload."""
    record = read_record(build_dir.parent / (case_file.stem + STATUS_SUFFIX))
    if record is None or record.status != "ok" or not (build_dir / MANIFEST).is_file():
        raise RuntimeError(f"{case_file}: no successful build in {build_dir}; run make cohort first")
    out_dir.mkdir(parents=True)
    manifest = json.loads((build_dir / MANIFEST).read_text(encoding="utf-8"))
    for name in (MANIFEST, KINEMATICS):
        shutil.copyfile(build_dir / name, out_dir / name)
    meshes = {}
    for name in sorted(mesh_names(build_dir)):
        (out_dir / name).parent.mkdir(parents=True, exist_ok=True)
        difference, full_faces, stored_faces = store_mesh(build_dir / name, out_dir / name, max_error_mm)
        meshes[name] = {**decimation_entry(difference), "faces_full": full_faces, "faces_stored": stored_faces}
        print(f"golden: {case_file.stem} {name}: {full_faces} -> {stored_faces} faces, "
              f"{difference.distance_max_mm:.4f} mm, volume {difference.volume_rel_change:+.2e}")
    return {
        "made_by": "make golden (pipelines/golden.py); do not edit by hand",
        "case": {"file": Path(os.path.relpath(case_file)).as_posix(), "sha256": sha256_file(case_file)},
        "inputs": [{"path": i["path"], "sha256": i["sha256"]} for i in manifest.get("inputs", [])],
        "versions": software_versions(),
        "decimation": DECIMATION.format(MAX_REDUCTION, max_error_mm),
        "meshes": meshes,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cohort", required=True, type=Path, help="folder of case files")
    parser.add_argument("--build", required=True, type=Path, help="where make cohort built them")
    parser.add_argument("--out", required=True, type=Path, help="the references folder (replaced)")
    parser.add_argument("--max-error-mm", type=float, default=MAX_ERROR_MM)
    args = parser.parse_args(argv)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{args.out.name}.new-", dir=args.out.parent))
    try:
        for case_file in cohort_cases(args.cohort):
            payload = store_case(case_file, args.build / case_file.stem, staging / case_file.stem, args.max_error_mm)
            (staging / case_file.stem / GOLDEN).write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
        old = args.out.with_name(f".{args.out.name}.old-{os.getpid()}")
        if args.out.exists():
            os.replace(args.out, old)
        os.replace(staging, args.out)
        shutil.rmtree(old, ignore_errors=True)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    size = sum(p.stat().st_size for p in args.out.rglob("*") if p.is_file())
    print(f"golden: references of {args.cohort} in {args.out} ({size / 1024:.0f} KiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
