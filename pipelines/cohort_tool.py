"""The commands pipelines/cohort.mk runs (see that file); each does one small job.

    cohort_tool.py deps CASE.yaml --target BUILD/<case>/manifest.json --out BUILD/.deps/<case>.mk
    cohort_tool.py run --case NAME --log BUILD/<case>.log --status BUILD/<case>.status.json [--exit-code] -- COMMAND...
    cohort_tool.py inputs --cohort DIR          (JSON: each case's existing input files; pipelines/Snakefile)
    cohort_tool.py summary --cohort DIR --build BUILD --out BUILD/cohort-summary.csv
    cohort_tool.py sample DATA_DIR      (writes the sample cohort's inputs, data/cohort)

``run`` exits 0, so that make goes on with the other cases (with
``--exit-code``, the build's exit code: Snakemake then marks the job failed
and goes on with ``--keep-going``); the summary exits 1 when any case
failed, after writing the table.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from softdesign import cohort
from softdesign.errors import SoftdesignError


def deps(args: argparse.Namespace) -> int:
    text = cohort.deps_text(Path(args.case), args.target, Path.cwd())
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    temporary = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    temporary.write_text(text, encoding="utf-8")
    os.replace(temporary, out)
    return 0


def run(args: argparse.Namespace) -> int:
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        print("cohort_tool.py run: give the build command after --", file=sys.stderr)
        return 2
    status = Path(args.status)
    cohort.write_record(cohort.RunRecord(args.case, "running", None, 0.0, "", args.log), status)
    record = cohort.run_logged(args.case, command, Path(args.log))
    cohort.write_record(record, status)
    if record.status == "ok":
        print(f"cohort: {args.case} built in {record.seconds:.1f} s")
    else:
        print(f"cohort: {args.case} FAILED (exit {record.exit_code}): {record.message} [log: {record.log}]")
        if args.exit_code:
            return record.exit_code if record.exit_code else 1
    return 0


def inputs(args: argparse.Namespace) -> int:
    found = {case.stem: cohort.existing_inputs(case, Path.cwd()) for case in cohort.cohort_cases(Path(args.cohort))}
    print(json.dumps(found, indent=1))
    return 0


def summary(args: argparse.Namespace) -> int:
    rows = cohort.summary_rows(Path(args.cohort), Path(args.build))
    kept = cohort.write_summary_csv(rows, Path(args.out))
    if kept is not None:
        print(f"cohort: the previous table is kept as {kept}")
    failed = [row for row in rows if row["status"] != "ok"]
    for row in rows:
        verdict = {"true": "feasible", "false": "NOT feasible", "not judged": "not judged"}.get(row["feasible"], "")
        print(f"  {row['case']:<24} {row['status']:<9} {verdict:<13} {_seconds(row['seconds'])}  "
              f"{row['message']}".rstrip())
    if failed:
        names = ", ".join(row["case"] for row in failed)
        print(f"cohort: {len(failed)} of {len(rows)} case(s) failed ({names}); table: {args.out}", file=sys.stderr)
        return 1
    print(f"cohort: {len(rows)} case(s) built; table: {args.out}")
    return 0


def sample(args: argparse.Namespace) -> int:
    from softdesign.samples.files import write_cohort

    for path in write_cohort(Path(args.out_dir)):
        print(f"wrote {path}")
    return 0


def _seconds(value) -> str:
    return f"{value:7.1f} s" if isinstance(value, float) else " " * 9


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="name", required=True)
    p = commands.add_parser("deps", help="write the make rule naming a case's input files")
    p.add_argument("case")
    p.add_argument("--target", required=True, help="the case's stamp, BUILD/<case>/manifest.json")
    p.add_argument("--out", required=True, help="the make fragment to write")
    p.set_defaults(action=deps)
    p = commands.add_parser("run", help="run one build with its output in a log and its status recorded")
    p.add_argument("--case", required=True)
    p.add_argument("--log", required=True)
    p.add_argument("--status", required=True)
    p.add_argument("--exit-code", action="store_true", help="exit with the build's exit code (default: 0)")
    p.add_argument("command", nargs=argparse.REMAINDER)
    p.set_defaults(action=run)
    p = commands.add_parser("inputs", help="print each case's existing input files as JSON")
    p.add_argument("--cohort", required=True)
    p.set_defaults(action=inputs)
    p = commands.add_parser("summary", help="write the one-row-per-case table; exit 1 when a case failed")
    p.add_argument("--cohort", required=True)
    p.add_argument("--build", required=True)
    p.add_argument("--out", required=True)
    p.set_defaults(action=summary)
    p = commands.add_parser("sample", help="write the sample cohort's input files")
    p.add_argument("out_dir")
    p.set_defaults(action=sample)
    args = parser.parse_args(argv)
    try:
        return args.action(args)
    except SoftdesignError as err:
        print(f"error: {err}", file=sys.stderr)
        return err.exit_code


if __name__ == "__main__":
    sys.exit(main())
