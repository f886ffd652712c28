"""The sample cohort built by `make -j2 cohort` once per run, for the two files that read it.

tests/e2e/test_golden.py checks its builds against tests/golden (CI's mesh guard) and tests/e2e/test_snakemake.py
builds the same cases with Snakemake and compares them with these.  Each had run `make -j2 cohort` on the four
sample cases; now the first to ask runs it, in the folder every xdist worker of the run shares
(tests/helpers/shared_builds.py, under its lock), and both only read what it made.

What is built: copies of configs/cohort/*.yaml and their inputs in the checkout's layout (the same bytes: a case's
input paths, relative to its file, hold), and ``broken.yaml``, the meander case with a misspelt key, which must fail
its row while the others build (what the Snakemake test compares make's table with).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.paths import REPO
from tests.helpers.shared_builds import made_once, shared_root

#: The sample cohort's case files in the checkout.
COHORT = REPO / "configs" / "cohort"
#: The sample cases, by name.
SAMPLE_CASES = tuple(sorted(p.stem for p in COHORT.glob("*.yaml")))
#: The case that fails: meander's case with its fit key misspelt (an unknown key, exit 2).
BROKEN = "broken"
#: What the make run left beside the build: its exit code and output.
RECORD = "make.json"


@dataclass(frozen=True)
class SampleCohort:
    """The copied case files, the build folder `make -j2 cohort` wrote, and how the make run ended."""

    cases: Path
    build: Path
    returncode: int
    output: str


def broken_case_text() -> str:
    """meander.yaml with ``knot_spacing_mm`` misspelt ``knot_spacng_mm``."""
    text = (COHORT / "meander.yaml").read_text(encoding="utf-8")
    assert "knot_spacing_mm" in text
    return text.replace("knot_spacing_mm", "knot_spacng_mm")


def _make_cohort(folder: Path) -> None:
    from tests.e2e.test_cohort import make, temporary_cohort

    folder.mkdir()
    cases = temporary_cohort(folder, names=SAMPLE_CASES)
    for name in SAMPLE_CASES:
        assert (cases / f"{name}.yaml").read_bytes() == (COHORT / f"{name}.yaml").read_bytes()
    (cases / f"{BROKEN}.yaml").write_text(broken_case_text(), encoding="utf-8")
    done = make("-j2", "cohort", cohort_dir=cases, build=folder / "build")
    record = {"returncode": done.returncode, "output": done.stdout + done.stderr}
    (folder / RECORD).write_text(json.dumps(record), encoding="utf-8")


def sample_cohort(factory: pytest.TempPathFactory) -> SampleCohort:
    """The sample cohort and the broken case built by `make -j2 cohort`, once per run (only read: copy to change)."""
    folder = made_once(shared_root(factory), "sample-cohort", _make_cohort)
    record = json.loads((folder / RECORD).read_text(encoding="utf-8"))
    return SampleCohort(folder / "configs" / "cohort", folder / "build", record["returncode"], record["output"])
