"""Benchmark of the volume_mesh stage (issue 32): "simulation-ready in seconds", at most 10 s per case.

Cases (the swept mesher, ``export.volume_mesh.q`` 0, 0.5 and 1 unless said):
the sample case solid (configs/demo.yaml); hollow (``wall_mm: 1``, ``port_mm:
1.2``); chambered (configs/actuator-per-chamber.yaml: three chambers per section with their
feeds, q = 0 as the case asks); and the VMTK aorta (path 0, when
../shared/data is there) solid, hollow as the demo, and chambered as
configs/actuator-per-chamber.yaml (four sections of three chambers).  Each case's stages before volume_mesh are built
once, untimed, into a temporary folder; then the volume_mesh stage alone
(compute: the mesh, its checks, the 3D strain at each q and over the morph's
q samples; write: the .vtu, .msh and cavity files) runs in this process,
timed as CPU seconds of this process and of its ended worker processes (the
machine's other load does not count: the target is judged on them) and as
wall seconds.  ``--jobs`` as ``softdesign build`` (default 1: CPU time does
not depend on it).

Usage: ``python pipelines/bench_volume.py [--jobs N] [--only CASE,...]`` (CASES below);
``make bench`` runs it after the build benchmark (pipelines/bench.py).
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from softdesign.pipeline.parallel import one_blas_thread

one_blas_thread()  # before numpy loads, as `softdesign` itself does

REPO = Path(__file__).resolve().parents[1]
AORTA_DIR = REPO.parent / "shared" / "data" / "vmtk-aorta"
#: Issue 32: a volume mesh in at most this many seconds per case (CPU s of the stage).
TARGET_S = 10.0
CASES = ("solid", "hollow", "chambered", "aorta", "aorta-hollow", "aorta-chambered")
#: ``export`` keys each case adds to its case file.
VOLUME_Q = {"volume_mesh": {"q": [0.0, 0.5, 1.0]}}


def case_data(name: str) -> dict[str, Any] | None:
    """The case file of benchmark case ``name`` as data, its inputs absolute (None: the aorta's data is absent)."""
    import yaml

    if name.startswith("aorta"):
        if not AORTA_DIR.is_dir():
            return None
        data: dict[str, Any] = {
            "name": name, "units": "mm",
            "final": {"centerline": str(AORTA_DIR / "aorta-centerline.vtp"),
                      "surface": str(AORTA_DIR / "aorta-surface.stl"), "path": 0},
            "export": {"q": [0.0, 0.5, 1.0], **VOLUME_Q}, "material": {"name": "ecoflex-00-30"}}
        if name == "aorta-hollow":
            data["export"].update({"wall_mm": 1.0, "port_mm": 1.2})
        if name == "aorta-chambered":  # configs/actuator-per-chamber.yaml's layout: four sections, three chambers each
            data.update({"links": {"count": 4}, "actuation": {}})
        return data
    source = REPO / "configs" / ("actuator-per-chamber.yaml" if name == "chambered" else "demo.yaml")
    data = yaml.safe_load(source.read_text(encoding="utf-8"))
    for key in ("centerline", "surface"):
        data["final"][key] = str((source.parent / data["final"][key]).resolve())
    data["name"] = name
    export = data.setdefault("export", {})
    export.pop("mould", None)  # not what is measured; its stage is left out of the upstream build
    if name == "hollow":
        export.update({"wall_mm": 1.0, "port_mm": 1.2})
    if name != "chambered":  # the actuator's case asks for q = 0 alone
        export.update(VOLUME_Q)
    return data


def _cpu_s() -> float:
    """CPU seconds of this process and of its ended workers (the stage's pool ends within the stage)."""
    own, workers = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + workers.ru_utime + workers.ru_stime


def measure(name: str, data: dict[str, Any], folder: Path, jobs: int) -> dict[str, Any]:
    """Build the stages before volume_mesh untimed, then time the volume_mesh stage's compute and write."""
    import yaml

    from softdesign.config import load_case
    from softdesign.pipeline.api import build_through
    from softdesign.pipeline.parallel import jobs_for_build
    from softdesign.pipeline.stage_order import STAGES
    from softdesign.pipeline.store import Staging

    case_file = folder / f"{name}.yaml"
    case_file.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    build = folder / f"build-{name}"
    build_through(case_file, build, target="actuation", jobs=jobs)
    case = load_case(case_file)
    results: dict[str, Any] = {}
    for stage in STAGES:
        if stage.name == "volume_mesh":
            break
        if stage.name not in ("export", "mould"):  # not upstream of volume_mesh
            results[stage.name] = stage.load(build, results)
    stage = next(s for s in STAGES if s.name == "volume_mesh")
    import meshio  # noqa: F401  (imported before the clock, as pipelines/bench.py does its libraries)

    import softdesign.pipeline.stages.volume_sweep  # noqa: F401

    wall, cpu = time.perf_counter(), _cpu_s()
    with jobs_for_build(jobs):
        result = stage.compute(case, results)
    middle = time.perf_counter(), _cpu_s()
    with Staging(folder / f"staged-{name}") as staging:
        stage.write(result, staging)
        written = sum(staging.staged_path(k).stat().st_size for k in staging.written)
    end = time.perf_counter(), _cpu_s()
    summary = result.summary
    return {"case": name, "tets": summary["per_q"][0]["tets"], "q": [f["q"] for f in summary["per_q"]],
            "compute_cpu_s": middle[1] - cpu, "write_cpu_s": end[1] - middle[1], "cpu_s": end[1] - cpu,
            "wall_s": end[0] - wall, "megabytes": written / 1e6, "morph": summary["morph"],
            "material": summary["material"]}


def row(r: dict[str, Any]) -> str:
    """One line of the table with the verdict against TARGET_S."""
    ok = r["cpu_s"] <= TARGET_S
    stretch, stress = r["morph"]["stretch_max"], r["morph"]["stress_max_kpa"]
    m = r["material"]
    limits = (f"stretch {stretch['value']:.4f} (max_stretch {m['max_stretch']:g}), stress "
              f"{stress['value']:.1f} kPa (tensile {m['tensile_strength_kpa']:.0f} kPa)" if stress else "")
    return (f"{r['case']:<10} {r['tets']:>8} {len(r['q']):>3} {r['compute_cpu_s']:>9.2f} {r['write_cpu_s']:>8.2f} "
            f"{r['cpu_s']:>7.2f} {r['wall_s']:>7.2f} {r['megabytes']:>6.1f}  <= {TARGET_S:g} s cpu: "
            f"{'met' if ok else 'MISSED'}; {limits}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=1, help="worker processes for the morph's q samples (default 1)")
    parser.add_argument("--only", default=",".join(CASES), help=f"cases, comma-separated, of {', '.join(CASES)}")
    parser.add_argument("--json", action="store_true", help="one JSON object per case instead of the table")
    args = parser.parse_args(argv)
    names = [n for n in args.only.split(",") if n]
    unknown = sorted(set(names) - set(CASES))
    if unknown:
        parser.error(f"--only: unknown case(s) {', '.join(unknown)}; expected some of {', '.join(CASES)}")
    if not args.json:
        print(f"volume_mesh stage (issue 32), swept mesher, --jobs {args.jobs}; cpu s = this process and its workers")
        print(f"{'case':<10} {'tets':>8} {'q':>3} {'compute s':>9} {'write s':>8} {'cpu s':>7} {'wall s':>7} "
              f"{'MB':>6}  target; largest over the morph vs the material")
    missed = False
    with tempfile.TemporaryDirectory(prefix="softdesign-bench-volume-") as scratch:
        for name in names:
            data = case_data(name)
            if data is None:
                print(f"{name:<10} skipped: {AORTA_DIR} not found", flush=True)
                continue
            r = measure(name, data, Path(scratch), args.jobs)
            missed |= r["cpu_s"] > TARGET_S
            print(json.dumps(r) if args.json else row(r), flush=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
