"""``make study``: re-derive the recorded nested-refinement study (tests/mechanics/refinement_reference.json).

Solves the study's section (tests/helpers/refinement_study.py) at its three levels, the finest about 9 minutes
on 2 cores, and writes every level's curvature, direction error and mesh size with how and when they were made.
``make test`` solves levels 0 and 1 afresh, checks them against this file and takes level 2 from it; run this
after a change to the mesher, the refinement or the solver moves them (the test says so), then commit the file.

Usage: ``python pipelines/study.py [--out FILE]``.
"""

from __future__ import annotations

import argparse
import datetime
import json
import platform
import sys
import time
from collections.abc import Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # the tests' helpers: the study is defined once, beside its test

from tests.helpers.refinement_study import LEVELS, REFERENCE, coarse_section, solve_level  # noqa: E402


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REFERENCE, help=f"where to write (default: {REFERENCE})")
    args = parser.parse_args(argv)
    coarse = coarse_section()
    levels = []
    for level in range(LEVELS):
        start = time.process_time()
        row = solve_level(coarse, level)
        row["cpu_s"] = round(time.process_time() - start, 1)
        levels.append(row)
        print(f"level {level}: kappa {row['kappa_per_mm']:.6e} 1/mm, direction off by "
              f"{row['phi_error_rad']:.3e} rad, {row['tets']} tets, {row['cpu_s']} s CPU", flush=True)
    document = {
        "made_by": "make study (python pipelines/study.py): tests/helpers/refinement_study.py at every level",
        "made_on": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d"),
        "python": f"{platform.python_implementation()} {platform.python_version()} on {platform.machine()}",
        "levels": levels,
    }
    tmp = args.out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(document, indent=2) + "\n", encoding="utf-8")
    tmp.replace(args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
