"""Benchmark of the design stage (issue 30): sections, chain deviation, tip error and time per case and tolerance.

Cases: the sample case (configs/demo.yaml), the VMTK aorta (path 0, when
../shared/data is there) and the sample case resampled to 1201 points.  Each
row is the design core (:func:`softdesign.kinematics.chain_design.design_chain`)
on the target the design stage builds, timed as CPU seconds of this process
(the machine's other load does not count) and wall seconds.  ``--before``
adds the previous programme (one arc per link from the vessel's own frame,
:mod:`softdesign.kinematics.arc_design`), its arcs composed from the base
and measured the same way (skipped at 1201 points: it takes about a minute).

Usage: ``python pipelines/bench_design.py [--before]``; ``make bench`` runs it
after the build benchmark (pipelines/bench.py).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

from softdesign.pipeline.parallel import one_blas_thread

one_blas_thread()  # before numpy loads, as `softdesign` itself does

import numpy as np  # noqa: E402

if TYPE_CHECKING:
    from softdesign.kinematics.chain_design import ChainTarget

REPO = Path(__file__).resolve().parents[1]
AORTA_DIR = REPO.parent / "shared" / "data" / "vmtk-aorta"
TOLERANCES_MM = (0.5, 1.0, 2.0)
#: Issue 30: at most this many seconds on the sample case and the aorta, and on a 1201-point centerline.
TARGET_S = {"demo": 2.0, "aorta": 2.0, "demo, 1201 points": 5.0}


def targets() -> list[tuple[str, ChainTarget, float]]:
    """(label, target, default shortest section mm) of every case, built as the design stage builds them."""
    from softdesign.config import load_case
    from softdesign.pipeline.stages.design import chain_target, final_curve
    from softdesign.pipeline.stages.ingest import run_ingest

    out = []
    demo = load_case(REPO / "configs" / "demo.yaml")
    cases = [("demo", demo)]
    if AORTA_DIR.is_dir():  # the aorta with the case file's defaults, as pipelines/bench.py builds it
        with tempfile.TemporaryDirectory() as folder:
            case_file = Path(folder) / "aorta.yaml"
            case_file.write_text(f"final: {{centerline: {json.dumps(str(AORTA_DIR / 'aorta-centerline.vtp'))}, "
                                 f"surface: {json.dumps(str(AORTA_DIR / 'aorta-surface.stl'))}, path: 0}}\n")
            cases.append(("aorta", load_case(case_file)))
    resample = demo.resample.model_copy(update={"count": 1201})
    cases.append(("demo, 1201 points", demo.model_copy(update={"resample": resample})))
    for label, case in cases:
        ingest = run_ingest(case)
        if ingest.path.radius is None:
            raise RuntimeError(f"{label}: the centerline has no radius for the default shortest section")
        shortest = float(2.0 * np.median(ingest.path.radius))
        out.append((label, chain_target(final_curve(case, ingest)), shortest))
    return out


def after(target: ChainTarget, tolerance: float, shortest: float) -> tuple[int, float, float, float, float, float]:
    from softdesign.kinematics.chain_design import ChainOptions, design_chain

    wall, cpu = time.perf_counter(), time.process_time()
    chain = design_chain(target, ChainOptions(tolerance, tolerance, None, shortest, 20))
    return (len(chain.length), chain.chain_max_deviation_mm, chain.tip_error_mm, chain.tip_error_deg,
            time.process_time() - cpu, time.perf_counter() - wall)


def before(target: ChainTarget, tolerance: float, shortest: float) -> tuple[int, float, float, float, float, float]:
    """The previous programme's links, their arcs composed from the base frame and measured as a design is."""
    from scipy.spatial import cKDTree

    from softdesign.kinematics.arc_design import DesignOptions, design_links
    from softdesign.kinematics.chain_design import _measure

    wall, cpu = time.perf_counter(), time.process_time()
    links = design_links(target.points, target.frames, target.arc_length, DesignOptions(tolerance, shortest, 200))
    seconds = time.process_time() - cpu, time.perf_counter() - wall
    w = np.array([[k.kappa * np.cos(k.phi), k.kappa * np.sin(k.phi)] for k in links.links])
    length = np.array([k.length for k in links.links])
    base = np.eye(4)
    base[:3, :3], base[:3, 3] = target.frames[0], target.points[0]
    chain = _measure(target, cKDTree(target.polyline), base, w, length)
    return (len(length), chain.chain_max_deviation_mm, chain.tip_error_mm, chain.tip_error_deg, *seconds)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", action="store_true", help="also run the previous programme (one arc per link)")
    args = parser.parse_args(argv)
    print(f"{'case':<18} {'T mm':>5} {'programme':<9} {'links':>5} {'chain mm':>9} {'tip mm':>7} {'tip deg':>7} "
          f"{'cpu s':>6} {'wall s':>6}  target")
    missed = False
    for label, target, shortest in targets():
        for tolerance in TOLERANCES_MM:
            rows = [("after", after(target, tolerance, shortest))]
            if args.before and len(target.points) <= 600:
                rows.append(("before", before(target, tolerance, shortest)))
            for name, (k, dev, tip, deg, cpu, wall) in rows:
                verdict = ""
                if name == "after":
                    ok = cpu <= TARGET_S[label]
                    missed |= not ok
                    verdict = f"<= {TARGET_S[label]:g} s cpu: {'met' if ok else 'MISSED'}"
                print(f"{label:<18} {tolerance:>5g} {name:<9} {k:>5} {dev:>9.3f} {tip:>7.3f} {deg:>7.2f} "
                      f"{cpu:>6.2f} {wall:>6.2f}  {verdict}", flush=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
