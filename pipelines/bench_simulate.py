"""Benchmark of `softdesign simulate` (issues 33, 42): one reinforced section of the sample case and of the aorta:
the forward solve against 30 s, the inverse against 60 s; the whole single-supply demo device at P* (issue 42,
``--all --q 1``) against 300 s.

Cases: configs/actuator-per-chamber.yaml (the sample vessel with seed 003's chambers) and
the VMTK aorta (path 0 of ../shared/data/vmtk-aorta, when present) with
``actuation: {}``, each at section 0 (the base, the thickest and the one every
feed line runs through).  Each case is first built through actuation (untimed:
the command then finds its build cached) and then run as a fresh process of
the console script, as a user runs it, timed wall clock from start to exit:

- the forward solve, ``--pressures FORWARD_KPA`` (one chamber), default mesh;
- the inverse, ``--target 1`` (the pressures that reach the designed arc at
  q = 1), default mesh, stopped by ``--timeout`` a little past the target so a
  slow search counts as missed without running for its default ten minutes.
  Neither case's arc at q = 1 is within reach of the finite elements at the
  default 100 kPa bound: the rod model itself asks 1090 kPa of the demo's
  section 1 (chamber 2) and 1628 kPa of the aorta's (chamber 1), and at 100 kPa
  the finite elements bend them 0.0041 of 0.042 and 0.00023 of 0.0070 1/mm,
  longer than the designed arcs, which pressure does not shorten.  So this line
  asks for the search's honest answer: it is met when, within the time, the
  search either converges or recognises the target as out of reach (its best
  within the bounds, ``best_within_bounds``); a search that stops short (time
  limit, stall) misses it;
- the inverse at a target the section can reach: the forward line's arc
  (``--pressures FORWARD_KPA``) searched back, ``--target-arc KAPPA,PHI,L``,
  met only when the search converges within the time; the line says how close
  the pressures come back to FORWARD_KPA.  A designed arc at a small q is not
  such a target: the designs shorten their sections and pressure lengthens
  them, so even where the rod model's pressures are a quarter of the bound
  (q = 0.0229 on the demo's section 1) the search stops at its best, 0.17 mm
  off, 0.166 mm of it length (measured).

Both cases take the default ``actuation.reinforcement`` (a kevlar hoop thread
round each chamber), which every pipeline solve now models.  Each line gives
the section mesh's nodes, the pressures, the remaining arc error (the
inverse), the largest principal stress against the tensile strength, the
command's wall time and the verdict against its target
(:data:`FORWARD_TARGET_S`, :data:`INVERSE_TARGET_S`).  Exit 1 when a target is
missed (its lines say which).  Issue 42 asks for the single-supply demo's
section at P*; ``simulate`` does not mesh ``supply: single``'s sized chambers
yet, so the forward line is the per-chamber demo's section at
:data:`FORWARD_KPA`.

Usage: ``python pipelines/bench_simulate.py``; ``make bench`` runs it after the
build benchmark (pipelines/bench.py).
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
AORTA_DIR = REPO.parent / "shared" / "data" / "vmtk-aorta"
#: Issue 42: one reinforced section's forward solve in at most this long on 2 cores, s.
FORWARD_TARGET_S = 30.0
#: Issues 33 and 42: an inverse per section in at most this long on 2 cores, s.
INVERSE_TARGET_S = 60.0
#: The forward solve's pressures, kPa (chamber 1 only: the section bends away from it).
FORWARD_KPA = "20,0,0"
#: The inverse's --timeout: past the target, so a miss is measured as one, but bounded, s.
INVERSE_TIMEOUT_S = 2.0 * INVERSE_TARGET_S

SECTION = 1  # numbered from 1 at the base, as --section takes it
#: Issue 42: the whole demo device (configs/actuator.yaml, single supply) at P* in at most this long on 2 cores, s.
DEVICE_TARGET_S = 300.0


def case_files(folder: Path) -> list[tuple[str, Path]]:
    """(label, case file) of the sample case with chambers and, when present, the aorta with chambers."""
    import yaml

    cases = [("demo (configs/actuator-per-chamber.yaml)", REPO / "configs" / "actuator-per-chamber.yaml")]
    if AORTA_DIR.is_dir():
        aorta = {"name": "aorta", "final": {"centerline": str(AORTA_DIR / "aorta-centerline.vtp"),
                                            "surface": str(AORTA_DIR / "aorta-surface.stl"), "path": 0},
                 "export": {"q": [0, 1]}, "actuation": {}, "material": {"name": "ecoflex-00-30"}}
        path = folder / "aorta.yaml"
        path.write_text(yaml.safe_dump(aorta, sort_keys=False), encoding="utf-8")
        cases.append(("aorta (path 0)", path))
    return cases


def softdesign() -> list[str]:
    """The console script beside this Python (as a user runs it)."""
    return [str(Path(sys.executable).with_name("softdesign"))]


def run(args: list[str]) -> tuple[float, dict | None, str]:
    """Wall seconds of ``softdesign simulate ARGS --json``, its JSON (None when it failed) and its last error line."""
    start = time.perf_counter()
    done = subprocess.run([*softdesign(), "simulate", *args, "--json"], capture_output=True, text=True, cwd=REPO)
    seconds = time.perf_counter() - start
    if done.returncode != 0 and not (done.returncode == 1 and done.stdout.strip()):
        return seconds, None, (done.stderr.strip().splitlines() or ["(no message)"])[-1]
    return seconds, json.loads(done.stdout), ""  # exit 1 with figures: a search that did not converge


def arc_text(payload: dict) -> str:
    """A payload's arc as ``--target-arc`` takes it: KAPPA,PHI,L (1/mm, degrees, mm), every digit kept."""
    arc = payload["arc"]
    return f"{arc['kappa_per_mm']!r},{math.degrees(arc['phi_rad'])!r},{arc['length_mm']!r}"


def answered(payload: dict, reachable: bool) -> bool:
    """Whether a run gave an answer: a forward solve, a converged search, or (when the target is not known to be
    reachable) a search that recognised it out of reach, at its best within the bounds."""
    found = payload.get("target")
    return found is None or found["converged"] or (not reachable and bool(found.get("best_within_bounds")))


def line(label: str, mode: str, target_s: float, seconds: float, payload: dict | None, error: str,
         reachable: bool = False, expected_kpa: str | None = None) -> tuple[str, bool]:
    """One row: the figures and the verdict against ``target_s`` (a failed run, or a search without an answer,
    :func:`answered`, misses the target); ``expected_kpa``: the pressures a round trip should come back to."""
    ok = payload is not None and seconds <= target_s and answered(payload, reachable)
    verdict = f"target <= {target_s:g} s: {'met' if ok else 'MISSED'}"
    if payload is None:
        return f"{label:<28} {mode:<18} {seconds:7.1f} s  failed: {error[:160]}  {verdict}", ok
    strength = payload["tensile_strength_kpa"]
    stress = f"stress {payload['max_stress_kpa']:.0f}" + (f"/{strength:.0f} kPa" if strength else " kPa")
    arc = ""
    if "target" in payload:
        found = payload["target"]
        arc = f", arc error {math.hypot(*found['error_mm']):.3f} mm" + (
            "" if found["converged"] else " (out of reach: its best within the bounds)"
            if found.get("best_within_bounds") else " (not converged)")
    pressures = ",".join(f"{p:.1f}" for p in payload["pressures_kpa"])
    if expected_kpa is not None:
        back = max(abs(p - float(e)) for p, e in zip(payload["pressures_kpa"], expected_kpa.split(","), strict=True))
        arc += f", pressures back within {back:.3g} kPa of {expected_kpa}"
    return (f"{label:<28} {mode:<18} {seconds:7.1f} s  {payload['mesh']['nodes']:>6} nodes, p {pressures} kPa{arc}, "
            f"{stress}  {verdict}"), ok


def device_line(seconds: float, payload: dict | None, error: str) -> tuple[str, bool]:
    """The whole device's row: its mesh, pressure, FE figures and the verdict against DEVICE_TARGET_S."""
    ok = payload is not None and seconds <= DEVICE_TARGET_S
    verdict = f"target <= {DEVICE_TARGET_S:g} s: {'met' if ok else 'MISSED'}"
    label = "demo device (configs/actuator.yaml) --all --q 1"
    if payload is None:
        return f"{label} {seconds:7.1f} s  failed: {error[:160]}  {verdict}", ok
    return (f"{label} {seconds:7.1f} s  {payload['mesh']['quadratic_nodes']} nodes, P {payload['pressure_kpa']:.1f} "
            f"kPa, within {payload['versus_design']['max_mm']:.3f} mm of the design, "
            f"{payload['versus_rod_model']['max_mm']:.3f} mm of the rod model, solve "
            f"{payload['seconds']['solve_cpu_s']:.0f} s CPU  {verdict}"), ok


def shown(row: tuple[str, bool]) -> bool:
    """Print a row; True when its target was missed."""
    print(row[0], flush=True)
    return not row[1]


def main(argv: list[str] | None = None) -> int:
    # no options: --help says what it runs (about ten minutes) instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    from softdesign.pipeline.api import build_through

    missed = False
    print(f"softdesign simulate, section {SECTION}, default mesh (--size-mm 3 --layer-mm 8), the case's hoop thread, "
          "wall s of the command:")
    with tempfile.TemporaryDirectory(prefix="softdesign-bench-simulate-") as scratch:
        for k, (label, case) in enumerate(case_files(Path(scratch))):
            out = Path(scratch) / f"build-{k}"
            build_through(case, out, "actuation")  # untimed: the command finds it cached
            common = [str(case), "--out", str(out), "--section", str(SECTION)]
            timeout = ["--timeout", f"{INVERSE_TIMEOUT_S:g}"]
            forward = run(common + ["--pressures", FORWARD_KPA])
            missed |= shown(line(label, f"--pressures {FORWARD_KPA}", FORWARD_TARGET_S, *forward))
            missed |= shown(line(label, "--target 1", INVERSE_TARGET_S, *run(common + ["--target", "1", *timeout])))
            back = f"--target-arc ({FORWARD_KPA}'s)"
            if forward[1] is None:  # no arc to search back
                missed |= shown(line(label, back, INVERSE_TARGET_S, 0.0, None, "the forward solve failed"))
            else:
                searched = run(common + ["--target-arc", arc_text(forward[1]), *timeout])
                missed |= shown(line(label, back, INVERSE_TARGET_S, *searched, reachable=True,
                                     expected_kpa=FORWARD_KPA))
        device, out = REPO / "configs" / "actuator.yaml", Path(scratch) / "build-device"
        build_through(device, out, "actuation")
        text, ok = device_line(*run([str(device), "--out", str(out), "--all", "--q", "1", "--timeout",
                                     f"{2 * DEVICE_TARGET_S:g}"]))
        missed |= not ok
        print(text, flush=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
