"""A cohort of cases built by make: dependency lists, one run record per case, the summary table.

``pipelines/cohort.mk`` drives this module through ``pipelines/cohort_tool.py``:

- :func:`deps_text` writes, per case, the make rule naming the files its
  build reads (the case file's inputs), so make rebuilds a case when one of
  them changes.  Every input is also listed as a target of its own with no
  recipe (as ``gcc -MP`` does): a missing input then makes that case fail in
  its build, with softdesign's message, instead of stopping make.
- :func:`run_logged` runs one case's build command with its output captured
  in ``BUILD/<case>.log`` and returns a :class:`RunRecord` (status, exit
  code, wall time, the error message), kept as ``BUILD/<case>.status.json``.
  A failed build leaves no new stamp: softdesign writes ``manifest.json``
  last and only when every stage succeeded.
- :func:`summary_rows` and :func:`write_summary_csv` make the one-row-per-case
  table from the run records and the manifests.
"""

from __future__ import annotations

import csv
import io
import json
import os
import subprocess
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import EXPORT_SUMMARY, FIT_SUMMARY, KINEMATICS, MANIFEST, MESHES_DIR

CASE_SUFFIX = ".yaml"
STATUS_SUFFIX = ".status.json"
#: Longest error message kept in the summary table (the log keeps all of it).
MESSAGE_CHARS = 400

SUMMARY_COLUMNS = (
    "case",
    "status",
    "seconds",
    "links",
    "fit_rms_mm",
    "fit_p99_mm",
    "fit_max_mm",
    "feasible",
    "skin_stretch_min",
    "skin_stretch_max",
    "wall_min_mm",
    "chain_deviation_mm",
    "tip_error_mm",
    "tip_error_deg",
    "axial_stretch_min",
    "axial_stretch_max",
    "max_rho_kappa",
    "min_radius_mm",
    "wall_mm",
    "meshes",
    "watertight",
    "volume_min_mm3",
    "volume_max_mm3",
    "volumes_mm3",
    "message",
    "log",
)


@dataclass(frozen=True)
class RunRecord:
    """How one case's last build went.

    Attributes
    ----------
    case : the case name (the case file's stem)
    status : ``ok``, ``failed`` or ``running`` (a run that was killed stays ``running``)
    exit_code : the build command's exit code (None while running)
    seconds : wall time of the build command
    message : the error message (the command's ``error:`` lines, or its last line), empty when ok
    log : the file holding the command's stdout and stderr
    """

    case: str
    status: str
    exit_code: int | None
    seconds: float
    message: str
    log: str

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready fields."""
        return asdict(self)


def cohort_cases(cohort_dir: Path) -> list[Path]:
    """The case files of a cohort folder (``*.yaml``), sorted by name.

    Raises
    ------
    ConfigError
        The folder does not exist or holds no case file.
    """
    cohort_dir = Path(cohort_dir)
    if not cohort_dir.is_dir():
        raise ConfigError(f"cohort folder {cohort_dir}: not found; give COHORT=DIR, a folder of case files")
    cases = sorted(cohort_dir.glob("*" + CASE_SUFFIX))
    if not cases:
        raise ConfigError(f"cohort folder {cohort_dir}: no *{CASE_SUFFIX} case files in it")
    return cases


def case_inputs(case_file: Path) -> list[Path]:
    """The files a build of ``case_file`` reads (present or not), as the case names them.

    Raises
    ------
    ConfigError
        The case file is missing or invalid.
    """
    # imported here: `run` and `summary` start once per case and need neither pydantic nor vtk
    from softdesign.config import load_case
    from softdesign.pipeline.inputs import input_fields

    return [path for _, path in input_fields(load_case(case_file))]


def deps_text(case_file: Path, target: str, relative_to: Path) -> str:
    """A make fragment: ``target`` depends on the case's input files.

    Paths are written relative to ``relative_to`` (make's working folder).  A
    case file that cannot be read gives a fragment with no inputs: its build
    then fails with softdesign's own message, and the fragment is remade when
    the case file changes.
    """
    header = f"# inputs of {case_file}, made by pipelines/cohort_tool.py deps; remade when the case file changes\n"
    try:
        inputs = case_inputs(case_file)
    except ConfigError:
        return header + "# the case file cannot be read: no inputs listed; its build says why\n"
    if not inputs:
        return header
    names = " ".join(_make_path(_near_path(p, relative_to)) for p in inputs)
    return header + f"{_make_path(Path(target))}: {names}\n{names}:\n"


def existing_inputs(case_file: Path, relative_to: Path) -> list[str]:
    """The case's input files that exist, relative to ``relative_to`` when inside it (for the Snakemake workflow).

    As with :func:`deps_text`, a missing input or an unreadable case file is left to the build to report
    (in the case's log and the summary), rather than stopping every other case before any starts.
    """
    try:
        inputs = case_inputs(case_file)
    except ConfigError:
        return []
    return [_near_path(p, relative_to).as_posix() for p in inputs if p.is_file()]


def _near_path(path: Path, relative_to: Path) -> Path:
    """``path`` relative to ``relative_to`` when it lies inside it, else absolute."""
    absolute = Path(os.path.abspath(path))
    try:
        return absolute.relative_to(Path(os.path.abspath(relative_to)))
    except ValueError:
        return absolute


def _make_path(path: Path) -> str:
    """A path as a make word: spaces, '#' and '$' escaped."""
    return path.as_posix().replace("$", "$$").replace("#", "\\#").replace(" ", "\\ ")


def run_logged(case: str, command: Sequence[str], log: Path) -> RunRecord:
    """Run ``command`` with stdout and stderr written to ``log``; never raises for a failing command."""
    log = Path(log)
    log.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    with log.open("wb") as handle:
        try:
            code = subprocess.run(list(command), stdout=handle, stderr=subprocess.STDOUT, check=False).returncode
        except OSError as err:  # the command itself cannot be started
            handle.write(f"error: cannot run {command[0]}: {err}\n".encode())
            code = 127
    seconds = time.perf_counter() - start
    status = "ok" if code == 0 else "failed"
    message = "" if code == 0 else error_message(log.read_text(encoding="utf-8", errors="replace"), code)
    return RunRecord(case, status, code, round(seconds, 3), message, log.as_posix())


def error_message(output: str, code: int) -> str:
    """The error a command reported: from its first ``error:`` line on, else its last line; one line."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    start = next((i for i, line in enumerate(lines) if line.startswith("error:")), None)
    if start is not None:
        text = " ".join(lines[start:]).removeprefix("error:").strip()
    else:
        text = lines[-1] if lines else f"exited with code {code} and no output"
    return text if len(text) <= MESSAGE_CHARS else text[: MESSAGE_CHARS - 3] + "..."


def write_record(record: RunRecord, path: Path) -> None:
    """Write a run record as JSON, atomically."""
    _write_atomically(Path(path), json.dumps(record.as_dict(), indent=2) + "\n")


def read_record(path: Path) -> RunRecord | None:
    """The run record at ``path``; None when there is none or it is unreadable."""
    try:
        return RunRecord(**json.loads(Path(path).read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        return None


def summary_rows(cohort_dir: Path, build_root: Path) -> list[dict[str, Any]]:
    """One row per case file of ``cohort_dir``, in name order (columns: SUMMARY_COLUMNS)."""
    rows = []
    for case_file in cohort_cases(cohort_dir):
        name = case_file.stem
        record = read_record(Path(build_root) / (name + STATUS_SUFFIX))
        rows.append(case_row(name, Path(build_root) / name, record))
    return rows


def case_row(name: str, build_dir: Path, record: RunRecord | None) -> dict[str, Any]:
    """The summary row of one case: its run record, and the manifest's figures when it built."""
    row: dict[str, Any] = {column: "" for column in SUMMARY_COLUMNS}
    row["case"] = name
    if record is None:
        row.update(status="not built", message="no run record: the case has not been built by make cohort")
        return row
    row.update(seconds=record.seconds, log=record.log)
    if record.status != "ok":
        interrupted = "the build was interrupted before it finished"
        row.update(status="failed", message=record.message if record.status == "failed" else interrupted)
        return row
    try:
        row.update(manifest_figures(build_dir))
    except (OSError, ValueError, KeyError, TypeError) as err:
        row.update(status="failed", message=f"{build_dir / MANIFEST}: unreadable after the build ({err})")
        return row
    row["status"] = "ok"
    return row


def manifest_figures(build_dir: Path) -> dict[str, Any]:
    """Fit, feasibility, design, stretch, rho*kappa, radius, wall and volume figures of a build folder's manifest.

    ``feasible`` is the build's one verdict (``manifest.verdict``: the skin, the chambers, the 3D figures and the
    mould; the feasibility stage's for a build made before it was recorded; ``not judged`` without a material),
    the same word the terminal and the report give; the skin's stretches are
    the extremes over the whole morph and the thinnest wall the least over the export q (feasibility), the axial
    stretches the centerline's.  ``meshes`` counts the exported q values (one mesh per q, whatever the number of
    formats), and ``volumes_mm3`` lists one volume per q.
    """
    build_dir = Path(build_dir)
    manifest = json.loads((build_dir / MANIFEST).read_text(encoding="utf-8"))
    metrics = manifest["metrics"]
    fit = metrics.get("fit") or {}
    per_q = _per_q_figures(build_dir, metrics)
    meshes = _one_mesh_per_q(manifest["outputs"])
    volumes = [float(o["volume_mm3"]) for o in meshes]
    design = metrics.get("design") or {}  # the composed-chain design (issue 30); blank without a design: block
    return {
        "links": (metrics.get("kinematics") or {}).get("links", ""),
        "fit_rms_mm": fit.get("rms_mm", ""),
        "fit_p99_mm": fit.get("p99_mm", ""),
        "fit_max_mm": fit.get("max_mm", ""),
        **_feasibility_figures(metrics.get("feasibility") or {}, manifest.get("verdict")),
        "chain_deviation_mm": design.get("chain_max_deviation_mm", ""),
        "tip_error_mm": design.get("tip_error_mm", ""),
        "tip_error_deg": design.get("tip_error_deg", ""),
        "axial_stretch_min": min((p["stretch_min"] for p in per_q), default=""),
        "axial_stretch_max": max((p["stretch_max"] for p in per_q), default=""),
        "max_rho_kappa": _max_rho_kappa(fit, build_dir),
        "min_radius_mm": _fit_summary(build_dir).get("min_rho_mm", ""),
        "wall_mm": manifest["case"]["export"].get("wall_mm") or "",
        "meshes": len(meshes),
        "watertight": all(o.get("watertight") for o in meshes) if meshes else "",
        "volume_min_mm3": min(volumes, default=""),
        "volume_max_mm3": max(volumes, default=""),
        "volumes_mm3": " ".join(f"{Path(o['path']).stem}={float(o['volume_mm3']):.6g}" for o in meshes),
    }


def _one_mesh_per_q(outputs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The exported body meshes (``meshes/q_*.<format>``), one per q: the first format listed for each."""
    by_q: dict[str, dict[str, Any]] = {}
    for o in outputs:
        path = Path(o["path"])
        if path.parent.as_posix() == MESHES_DIR and path.stem.startswith("q_") and "volume_mm3" in o:
            by_q.setdefault(path.stem, o)
    return [by_q[q] for q in sorted(by_q)]


def _feasibility_figures(block: dict[str, Any], record: dict[str, Any] | None = None) -> dict[str, Any]:
    """The verdict (``record``, the manifest's, when it has one), the skin's stretch extremes over the morph and
    the thinnest wall over the export q."""
    if not block or "morph" not in block:
        return {"feasible": "", "skin_stretch_min": "", "skin_stretch_max": "", "wall_min_mm": ""}
    walls = [row["wall_min_mm"] for row in block.get("per_q", []) if row.get("wall_min_mm") is not None]
    verdict = record.get("feasible") if isinstance(record, dict) and "feasible" in record else block.get("feasible")
    return {
        "feasible": "not judged" if verdict is None else str(bool(verdict)).lower(),
        "skin_stretch_min": block["morph"]["stretch_min"]["value"],
        "skin_stretch_max": block["morph"]["stretch_max"]["value"],
        "wall_min_mm": min(walls, default=""),
    }


def _per_q_figures(build_dir: Path, metrics: dict) -> list[dict]:
    """Length, stretch and curvature of the centerline per export q (kinematics.json, else the blend metrics)."""
    path = build_dir / KINEMATICS
    if path.is_file():
        per_q = json.loads(path.read_text(encoding="utf-8")).get("per_q")
        if per_q:
            return per_q
    return (metrics.get("blend") or {}).get("per_q") or []


def _max_rho_kappa(fit: dict, build_dir: Path) -> Any:
    """The largest rho * kappa over the exported meshes (it folds at 1), else the fit's at q = 1."""
    path = build_dir / EXPORT_SUMMARY
    if path.is_file():
        meshes = json.loads(path.read_text(encoding="utf-8")).get("meshes", {})
        values = [m["max_rho_kappa"] for m in meshes.values() if "max_rho_kappa" in m]
        if values:
            return max(values)
    return fit.get("max_rho_kappa", "")


def _fit_summary(build_dir: Path) -> dict:
    path = build_dir / FIT_SUMMARY
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}


def summary_csv(rows: list[dict[str, Any]]) -> str:
    """The table as CSV text: a header row, then one row per case; floats with 6 significant digits."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=SUMMARY_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: f"{v:.6g}" if isinstance(v, float) else v for k, v in row.items()})
    return buffer.getvalue()


def write_summary_csv(rows: list[dict[str, Any]], path: Path) -> Path | None:
    """Write the summary table, atomically (a reader never sees half a table), keeping a different older one.

    A table already at ``path`` with other content is kept as ``<stem>.<k>.csv`` beside it (k the next free
    number, from 1), so a run never silently destroys the last one; the kept table's path is returned (None
    when there was none, or it was the same).
    """
    path = Path(path)
    text = summary_csv(rows)
    kept = None
    if path.is_file() and path.read_text(encoding="utf-8") != text:
        k = 1
        while path.with_name(f"{path.stem}.{k}{path.suffix}").exists():
            k += 1
        kept = path.with_name(f"{path.stem}.{k}{path.suffix}")
        os.link(path, kept)  # a second name for the old table; the new one then replaces the first
    _write_atomically(path, text)
    return kept


def _write_atomically(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
