"""The cohort on Snakemake (pipelines/Snakefile, profiles/slurm): the same builds, logs and table as `make cohort`.

Snakemake lives in its own venv, .venv-cluster (`make install` puts it there, pinned by
requirements/cluster.txt).  Every run works in a temporary folder, so its .snakemake/
bookkeeping stays out of the checkout.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from softdesign.cohort import existing_inputs
from tests.e2e.test_cohort import needs_make, temporary_cohort
from tests.helpers.paths import REPO
from tests.helpers.sample_cohort import SAMPLE_CASES, sample_cohort

SNAKEFILE = REPO / "pipelines" / "Snakefile"
SLURM_PROFILE = REPO / "profiles" / "slurm"
#: Summary columns that differ between two runs of the same builds (wall time, where the log is).
RUN_COLUMNS = ("seconds", "log")


def snakemake_command() -> list[str]:
    """The pinned snakemake of .venv-cluster (else one on PATH)."""
    pinned = REPO / ".venv-cluster" / "bin" / "snakemake"
    found = str(pinned) if pinned.is_file() else shutil.which("snakemake")
    if found is None:
        pytest.fail("snakemake not found: `make install` puts it in .venv-cluster (pyproject's [cluster] extra)")
    return [found]


def snakemake(*args: str, cohort_dir: Path, build: Path, cwd: Path) -> subprocess.CompletedProcess:
    """snakemake on pipelines/Snakefile with this interpreter's softdesign, working in ``cwd``."""
    softdesign = Path(sys.executable).with_name("softdesign")
    config = [f"cohort={cohort_dir}", f"build={build}", f"python={sys.executable}"]
    config += [f"softdesign={softdesign}"] if softdesign.is_file() else []
    command = [*snakemake_command(), "-s", str(SNAKEFILE), *args, "--config", *config]
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}  # as on a machine without SLURM
    return subprocess.run(command, capture_output=True, text=True, timeout=900, cwd=cwd, env=env,
                          stdin=subprocess.DEVNULL)


def summary_rows(build: Path) -> dict[str, dict[str, str]]:
    with (build / "cohort-summary.csv").open(newline="") as handle:
        rows = {row["case"]: row for row in csv.DictReader(handle)}
    for row in rows.values():
        for column in RUN_COLUMNS:
            row.pop(column)
    return rows


def test_dry_run_with_the_slurm_profile_plans_one_build_per_case(tmp_path):
    build = tmp_path / "build"
    done = snakemake("-n", "--profile", str(SLURM_PROFILE), cohort_dir=REPO / "configs" / "cohort", build=build,
                     cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    out = done.stdout + done.stderr
    for case in SAMPLE_CASES:
        assert out.count(f"build {REPO}/configs/cohort/{case}.yaml --out {build}/{case} --jobs") == 1, case
        assert f"--log {build}/{case}.log --status {build}/{case}.status.json" in out
    # the profile's per-build memory and time reach the build jobs (and only them), then one table
    assert out.count("mem_mb=4096") == len(SAMPLE_CASES) and out.count("runtime=30") == len(SAMPLE_CASES)
    assert out.count("rule build:") == len(SAMPLE_CASES) and out.count("rule summary:") == 1
    assert not build.exists()  # a dry run builds nothing


def test_the_dry_run_lists_the_inputs_a_case_names(tmp_path):
    cases = temporary_cohort(tmp_path, names=("s_bend",))
    done = snakemake("-n", "--cores", "1", cohort_dir=cases, build=tmp_path / "build", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    inputs = next(line for line in done.stdout.splitlines() if "s_bend.yaml" in line and "input:" in line)
    assert "data/cohort/s_bend/centerline.vtp" in inputs and "data/cohort/s_bend/surface.ply" in inputs


def test_existing_inputs_leave_a_missing_file_and_a_bad_case_to_the_build(tmp_path):
    cases = temporary_cohort(tmp_path, names=("s_bend",))
    assert existing_inputs(cases / "s_bend.yaml", tmp_path) == ["data/cohort/s_bend/centerline.vtp",
                                                                 "data/cohort/s_bend/surface.ply"]
    (tmp_path / "data" / "cohort" / "s_bend" / "surface.ply").unlink()
    assert existing_inputs(cases / "s_bend.yaml", tmp_path) == ["data/cohort/s_bend/centerline.vtp"]
    (cases / "bad.yaml").write_text("final: {centerline: c.vtp}\nknots: 3\n")
    assert existing_inputs(cases / "bad.yaml", tmp_path) == []


@pytest.mark.slow
@needs_make
def test_snakemake_builds_the_sample_cohort_as_make_cohort_does(tmp_path, tmp_path_factory):
    # the sample cases and the broken one, built by `make -j2 cohort` once per run (tests/helpers/sample_cohort.py,
    # read by tests/e2e/test_golden.py too): their case files are the ones Snakemake builds here, into a folder of
    # its own
    cohort = sample_cohort(tmp_path_factory)
    cases, by_make, by_snakemake = cohort.cases, cohort.build, tmp_path / "snakemake"
    assert cohort.returncode != 0, cohort.output  # the broken case
    done = snakemake("--cores", "2", "--keep-going", cohort_dir=cases, build=by_snakemake, cwd=tmp_path)
    assert done.returncode != 0, "the broken case must fail the run"

    # the same table (but for wall times and log paths), the same logs and status records
    rows = summary_rows(by_snakemake)
    assert rows == summary_rows(by_make)
    assert {name: row["status"] for name, row in rows.items()} == {"broken": "failed"} | dict.fromkeys(
        SAMPLE_CASES, "ok")
    assert "unknown key 'knot_spacng_mm'" in rows["broken"]["message"]
    for name in ("broken", *SAMPLE_CASES):
        status = json.loads((by_snakemake / f"{name}.status.json").read_text())
        assert status["exit_code"] == (2 if name == "broken" else 0)
        assert (by_snakemake / f"{name}.log").is_file()
    assert not (by_snakemake / "broken" / "manifest.json").exists()

    # every build matches make's by softdesign check (meshes, kinematics, fit metrics), in this process: the check's
    # verdict is the point here, not its process (a child each cost about 1.5 s of CPU in start-up and imports)
    from typer.testing import CliRunner

    from softdesign.cli import app

    for name in SAMPLE_CASES:
        check = CliRunner().invoke(app, ["check", str(by_snakemake / name), "--reference", str(by_make / name)])
        assert check.exit_code == 0, check.output

    # a second run builds only the failed case again
    again = snakemake("-n", "-p", "--cores", "2", cohort_dir=cases, build=by_snakemake, cwd=tmp_path)
    planned = {name for name in ("broken", *SAMPLE_CASES) if f"--out {by_snakemake}/{name} " in again.stdout}
    assert planned == {"broken"}, again.stdout
