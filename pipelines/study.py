"""``make study``: re-derive the recorded nested-refinement studies (tests/mechanics/refinement_reference*.json).

Solves each study's section (tests/helpers/refinement_study.py: bare, with the sample case's hoop thread, and
threaded with round chambers; or, when asked, with that thread under the six-point rule) at each of its levels
(three, the finest 12-25 minutes of CPU; two for round chambers), and writes every level's curvature, direction
error, mesh size, Newton iterations and CPU time with how and when they were made.  ``make test`` solves level 0
afresh, checks it and the refined meshes' sizes against these files and takes the finer levels from them; run
this after a change to the mesher, the refinement, the thread or the solver moves them (the tests say so), then
commit the files.

Usage: ``python pipelines/study.py [--study NAME ...] [--out FILE]`` (``--out`` with one study only).
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # the tests' helpers: each study is defined once, beside its test

from tests.helpers.fibre_rules import six_point_share  # noqa: E402
from tests.helpers.refinement_study import (  # noqa: E402
    LEVELS,
    RECORDED,
    STUDIES,
    STUDY_KPA,
    Study,
    coarse_section,
    observed_order,
    solve_level,
)


def run_study(study: Study, out: Path) -> None:
    """Solve ``study`` at every level, print each, and write its record to ``out`` (whole, or not at all)."""
    coarse = coarse_section(study.ring_count, study.curved)
    levels: list[dict[str, Any]] = []
    for level in range(study.levels):
        row = solve_level(coarse, level, study)
        levels.append(row)
        print(f"{study.name} level {level}: kappa {row['kappa_per_mm']:.6e} 1/mm, direction off by "
              f"{row['phi_error_rad']:.3e} rad, {row['tets']} tets, {row['iterations']} Newton iterations, "
              f"{row['cpu_s']} s CPU", flush=True)
    kappas = np.array([row["kappa_per_mm"] for row in levels])
    changes = ", ".join(f"{100 * change:+.2f} %" for change in kappas[1:] / kappas[:-1] - 1)
    if len(kappas) == LEVELS:
        order, extrapolated = observed_order(kappas)
        changes += f"; order {order:.2f}; Richardson {extrapolated:.6e} 1/mm"
    print(f"{study.name}: changes {changes}")
    thread = study.thread()
    document = {
        "made_by": "make study (python pipelines/study.py): tests/helpers/refinement_study.py at every level",
        "made_on": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d"),
        "python": f"{platform.python_implementation()} {platform.python_version()} on {platform.machine()}",
        "study": study.name,
        "pressure_kpa": STUDY_KPA,
        "ring_count": study.ring_count,
        "curved_walls": study.curved,
        "thread": None if thread is None else {"pitch_mm": thread.pitch_mm, "diameter_mm": thread.diameter_mm,
                                               "modulus_kpa": thread.modulus_kpa, "rule": study.rule,
                                               "six_point_share": six_point_share(study.rule)},
        "levels": levels,
    }
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    tmp.replace(out)
    print(f"wrote {out}", flush=True)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", action="append", choices=sorted(STUDIES),
                        help=f"a study to re-derive (repeat for more; default: {', '.join(RECORDED)}: the tests' "
                             "records)")
    parser.add_argument("--out", type=Path, help="where to write (one study only; default: its recorded file)")
    args = parser.parse_args(argv)
    names = args.study or list(RECORDED)
    if args.out is not None and len(names) != 1:
        parser.error(f"--out names one file: give one --study, got {len(names)}")
    for name in names:
        run_study(STUDIES[name], args.out or STUDIES[name].reference)
    return 0


if __name__ == "__main__":
    sys.exit(main())
