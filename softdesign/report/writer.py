"""Write ``BUILD_DIR/report/``: every figure, the GIF and ``index.html``, all at once.

The files are written into a hidden temporary folder beside ``report/`` and
moved into place only when all of them exist: a failed or killed run leaves
the previous report as it was (a killed run's temporary folder is removed by
a later run).  The build folder's stage outputs and
manifest are only read.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import MANIFEST, REPORT_DIR, RUN_LOG
from softdesign.pipeline.lock import BuildLock
from softdesign.pipeline.out_folder import folder_errors
from softdesign.report import (
    actuation_figures,
    animation,
    design_figures,
    fit_figures,
    interactive,
    interactive_parts,
    kinematics_figures,
    morph_figures,
    mould_figures,
    profile_figures,
    simulate_panel,
    stretch_figures,
    surface_figures,
)
from softdesign.report.build_check import changed_since_build, unreadable_build
from softdesign.report.build_folder import BuildData, load_build, require_build
from softdesign.report.commit import commit_folder
from softdesign.report.drawing_run import PartTimer, Progress, collector_for_figures
from softdesign.report.html_page import (
    Section,
    banner_html,
    compact_check_tables,
    key_figure_table,
    plain_table,
    referenced_files,
    render_page,
    table_html,
)
from softdesign.report.make_it import make_it_section
from softdesign.report.plotting import pixel_size
from softdesign.report.summary import facts_table, summary_facts, summary_warnings
from softdesign.report.tables import (
    Check,
    fit_checks,
    input_rows,
    key_figures,
    mesh_checks,
    output_checks,
    software_rows,
)
from softdesign.report.verdict import build_verdict, checks_html, verdict_html
from softdesign.report.volume_mesh_tables import volume_mesh_checks, volume_mesh_table

PAGE = "index.html"
#: What differs from run to run or folder to folder (the build folder's path, the build's and the report's times):
#: kept out of the page, which is the same bytes for the same build wherever it is, and written here.
LOG = "report.log"
NO_FIT = (
    "no fit in this build folder (built only through kinematics): surfaces and fit quality are left out; "
    "run softdesign build"
)
NO_EXPORT = "no export in this build folder: no mesh checks; run softdesign build"
#: Pixel (width, height) of every image the report can hold.
EXPECTED_SIZES = {
    "morph.png": pixel_size(morph_figures.SIZE_IN),
    "surfaces.png": pixel_size(surface_figures.SIZE_IN),
    "fit_residuals.png": pixel_size(fit_figures.RESIDUAL_SIZE_IN),
    "fit_distances.png": pixel_size(fit_figures.DISTANCE_SIZE_IN),
    "kinematics.png": pixel_size(kinematics_figures.SIZE_IN),
    "pcc_chambers.png": pixel_size(kinematics_figures.PCC_SIZE_IN),
    "design.png": pixel_size(design_figures.SIZE_IN),
    "morph.gif": pixel_size(animation.SIZE_IN),
    stretch_figures.NAME: pixel_size(stretch_figures.SIZE_IN),
    mould_figures.NAME: mould_figures.PIXEL_SIZE,
    profile_figures.NAME: pixel_size(profile_figures.SIZE_IN),
    actuation_figures.NAME: pixel_size(actuation_figures.SIZE_IN),
    simulate_panel.NAME: pixel_size(simulate_panel.SIZE_IN),
}


@dataclass(frozen=True)
class ReportOptions:
    """What to draw: PCC chamber distance(s) d in mm (None: no PCC panel), q samples, GIF frames."""

    pcc_d: tuple[float, ...] | None = None
    q_samples: int = kinematics_figures.Q_SAMPLES
    gif_frames: int = animation.FRAMES
    view_frames: int = interactive.FRAMES


@dataclass(frozen=True)
class ReportResult:
    """Where the page is, each file's size in bytes, the checks' tally and what was left out."""

    page: Path
    files: dict[str, int]
    checks_passed: int
    checks_total: int
    notes: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)  #: time of each part, s (not written to the page)
    warnings: list[str] = field(default_factory=list)  #: the failed checks (the build's warnings: its manifest)


def write_report(
    build_dir: str | Path, options: ReportOptions = ReportOptions(), progress: Progress | None = None, jobs: int = 1
) -> ReportResult:
    """Draw the report of ``build_dir`` into ``build_dir/report/`` (replacing an older one).

    ``progress(name, seconds)`` is called after each part (loading, each figure, the page, the write).
    ``jobs``: worker processes drawing the slow figures side by side (checked by the caller,
    :func:`softdesign.pipeline.parallel.checked_jobs`); the files are the same bytes whatever it is.

    Raises
    ------
    InputDataError
        ``build_dir`` is not a build folder or a required stage's files are missing.
    SoftdesignError
        A PCC design fails (e.g. a bad ``pcc_d``).
    """
    # under the build's lock from the first read to the last write: a build cannot change the folder meanwhile, so
    # the page shows one build; OSErrors name the folder, exit 2
    require_build(Path(build_dir))  # before the lock: a folder that is not a build gets no lock file beside it
    with folder_errors(Path(build_dir)), BuildLock(Path(os.path.realpath(build_dir))) as lock:
        try:
            result = _write_report(Path(build_dir), options, progress, jobs)
        except (KeyError, TypeError, IndexError, ValueError, AttributeError) as err:  # the build's files lack a key
            manifest = json.loads((Path(build_dir) / MANIFEST).read_text(encoding="utf-8"))
            raise unreadable_build(Path(build_dir), changed_since_build(Path(build_dir), manifest), err) from err
    result.notes[:0] = lock.notes
    return result


def _write_report(build_dir: Path, options: ReportOptions, progress: Progress | None, jobs: int) -> ReportResult:
    timer = PartTimer(progress, jobs)
    data = timer("load the build", lambda: load_build(build_dir))
    with collector_for_figures(data, jobs):
        sections, checks, notes = report_sections(data, options, timer)
    passed = sum(c.passed for c in checks)
    summary = _summary(data)
    warnings, build_notes = summary_warnings(data.manifest)
    # the verdict, the warnings (the manifest's: the terminal's same lines), then the checks folded, then the figures
    top = timer("summary", lambda: verdict_html(build_verdict(data.manifest)) + banner_html(warnings, build_notes)
                + checks_html(checks) + table_html(facts_table(summary_facts(data), data.manifest)))
    page = render_page(f"softdesign report: {data.name}", summary, sections, top)
    files = {p.name: p.data for s in sections for p in s.pictures}
    files[PAGE] = page.encode("utf-8")
    if any(interactive.JS_NAME in embed for s in sections for embed in s.embeds):
        files[interactive.JS_NAME] = interactive.plotly_js()
    files[LOG] = run_log(data, timer.seconds)
    missing = sorted(set(referenced_files(page)) - set(files))
    if missing:
        raise RuntimeError(f"report page links to files it does not write: {missing}")  # a bug, not a user error
    target = build_dir / REPORT_DIR
    timer("write the files", lambda: commit_folder(target, files))
    failed = [f"check failed: {c.subject}: {c.name}" for c in checks if not c.passed]
    return ReportResult(target / PAGE, {k: len(v) for k, v in sorted(files.items())}, passed, len(checks), notes,
                        timer.seconds, failed)


def report_sections(
    data: BuildData, options: ReportOptions, timer: PartTimer | None = None
) -> tuple[list[Section], list[Check], list[str]]:
    """The sections of the page, every check, and the notes on what was left out."""
    check_pcc_count(data, options)  # before any drawing: a bad count is refused at once
    run = timer or PartTimer(None)
    run.prefetch(_slow_parts(data, options))
    notes: list[str] = []
    view = _view_section(data, options, run)
    morph = Section("morph", "The morph", pictures=[
        run("morph.png", lambda: morph_figures.morph_picture(data.kinematics.chain, data.export_q))
    ])
    surfaces, fit = Section("surfaces", "The surfaces"), Section("fit", "Fit quality")
    if data.fit is None:
        notes.append(NO_FIT)
        surfaces.notes.append(NO_FIT)
        fit.notes.append(NO_FIT)
    else:
        surface = run("surfaces.png", lambda: surface_figures.surface_picture(data))  # None only without a fit
        if surface is not None:
            surfaces.pictures.append(surface)
        profile = run(profile_figures.NAME, lambda: profile_figures.profile_picture(data))
        if profile is not None:
            surfaces.pictures.append(profile)
        fit.pictures.extend([run("fit_residuals.png", lambda: fit_figures.residual_picture(data)),
                             run("fit_distances.png", lambda: _distance_picture(data))])
    kinematics = _kinematics_section(data, options, notes, run)
    field = data.fit.field if data.fit is not None else None
    gif = run("morph.gif", lambda: animation.morph_gif(data.kinematics.chain, field, options.gif_frames))
    tables, checks = run("tables and checks", lambda: _tables_section(data))
    if data.export_summary is None:
        notes.append(NO_EXPORT)
        tables.notes.append(NO_EXPORT)
    design = Section(
        "design", design_figures.panel_title(data.build_dir),
        pictures=[run("design.png", lambda: design_figures.panel_picture(data.kinematics.chain, data.build_dir))],
    )
    sections = [
        view, morph, surfaces, fit, kinematics, design, tables,
        Section("animation", "The morph, animated", pictures=[gif]),
    ]
    stretch = run(stretch_figures.NAME, lambda: stretch_figures.stretch_picture(data))
    if stretch is not None:
        sections.insert(4, Section("feasibility", "Skin stretch and wall", pictures=[stretch]))
    actuation = run(actuation_figures.NAME, lambda: actuation_figures.actuation_picture(data))
    if actuation is not None:
        sections.insert(5, Section("actuation", "Actuation: chambers, feeds, lengths", pictures=[actuation]))
    simulated = run(simulate_panel.NAME, lambda: simulate_panel.simulate_picture(data))
    if simulated is not None:
        at = next(k for k, s in enumerate(sections) if s.anchor in ("actuation", "tables")) + 1
        sections.insert(at, Section("simulate", "What pressure bends it: simulated sections", pictures=[simulated]))
    fabrication = _fabrication_section(data, run)
    if fabrication is not None:
        sections.insert(-2, fabrication)
    make_it = make_it_section(data.manifest)  # fabrication.md's lines: how to make it, from the build's figures
    if make_it is not None:
        sections.insert(-2, make_it)
    return sections, checks, notes


def check_pcc_count(data: BuildData, options: ReportOptions) -> None:
    """Refuse a ``--pcc-d`` that gives neither one distance nor one per link of the build (ConfigError, exit 2)."""
    if options.pcc_d is not None and len(options.pcc_d) not in (1, data.link_count):
        raise ConfigError(
            f"--pcc-d: got {len(options.pcc_d)} distances, the build has {data.link_count} link(s); "
            f"give one value for every link or {data.link_count}, one per link"
        )


def _slow_parts(data: BuildData, options: ReportOptions) -> dict[str, Callable[[], Any]]:
    """The parts that take seconds and need only ``data``, slowest first (as measured on the demo)."""
    field = data.fit.field if data.fit is not None else None
    parts: dict[str, Callable[[], Any]] = {
        "morph.gif": lambda: animation.morph_gif(data.kinematics.chain, field, options.gif_frames),
        stretch_figures.NAME: lambda: stretch_figures.stretch_picture(data),
        "3D view": lambda: interactive.morph_html(data, options.view_frames),
        "morph.png": lambda: morph_figures.morph_picture(data.kinematics.chain, data.export_q),
    }
    if data.fit is not None:
        parts["surfaces.png"] = lambda: surface_figures.surface_picture(data)
    parts["kinematics.png"] = lambda: _kinematics_picture(data, options)
    if data.fit is not None:
        parts["fit_distances.png"] = lambda: _distance_picture(data)
        parts["fit_residuals.png"] = lambda: fit_figures.residual_picture(data)
        parts[profile_figures.NAME] = lambda: profile_figures.profile_picture(data)
    parts["design.png"] = lambda: design_figures.panel_picture(data.kinematics.chain, data.build_dir)
    parts[mould_figures.NAME] = lambda: mould_figures.mould_picture(data)
    return parts


def _distance_picture(data: BuildData) -> Any:
    """The true distances' figure (a build with a fit)."""
    return fit_figures.distance_picture(data, fit_figures.true_distances(data))


def _kinematics_picture(data: BuildData, options: ReportOptions) -> Any:
    """The kinematics over q figure."""
    series = kinematics_figures.kinematics_series(data.kinematics.chain, data.export_q, options.q_samples)
    return kinematics_figures.kinematics_picture(series)


def _fabrication_section(data: BuildData, run: PartTimer) -> Section | None:
    """The casting mould (exploded view) and the volume meshes' quality, when the build has them."""
    mould = run(mould_figures.NAME, lambda: mould_figures.mould_picture(data))
    table = volume_mesh_table(_volume_summary(data))
    if mould is None and table is None:
        return None
    section = Section("fabrication", "Fabrication: casting mould and volume meshes")
    if mould is not None:
        section.pictures.append(mould)
    if table is not None:
        section.tables.append(table)
        section.notes.append("fTetWild is not deterministic: the volume meshes differ between runs of the mesher; "
                             "their checks hold for every run.")
    return section


def _volume_summary(data: BuildData) -> dict[str, Any] | None:
    """The volume_mesh stage's summary (manifest metrics), or None when the build has none."""
    block = data.manifest.get("metrics", {}).get("volume_mesh")
    return block if isinstance(block, dict) else None


def _view_section(data: BuildData, options: ReportOptions, run: PartTimer) -> Section:
    """The interactive 3D view of the morph over the patient's vessel."""
    html, display_notes = run("3D view", lambda: interactive.morph_html(data, options.view_frames))
    what = "the actuator (coloured by link)" if data.fit is not None else "the centerline (no fit in this build)"
    note = (f"{what} at {options.view_frames} q values from 0 to 1 (slider, play), its centerline per link, and the "
            "patient's vessel surface, semi-transparent; drag to turn, scroll to zoom. "
            + interactive_parts.hidden_parts_note(data)
            + "Decimated for display only: "
            + "; ".join(display_notes) + ". Needs JavaScript; nothing is fetched from the network.")
    return Section("view", "The morph in 3D (interactive)", notes=[note], embeds=[html])


def _kinematics_section(data: BuildData, options: ReportOptions, notes: list[str], run: PartTimer) -> Section:
    section = Section("kinematics", "Kinematics over q",
                      pictures=[run("kinematics.png", lambda: _kinematics_picture(data, options))])
    if options.pcc_d is None:
        section.notes.append("PCC chamber lengths: not drawn; give --pcc-d D (mm, one or one per link) to add them.")
        return section
    try:
        import softdesign.kinematics.pcc_fit  # noqa: F401  (the PCC design module is optional)
    except ImportError:
        note = "PCC chamber lengths: left out, this installation has no PCC design (softdesign.kinematics.pcc_fit)."
        section.notes.append(note)
        notes.append(note)
        return section
    d = options.pcc_d[0] if len(options.pcc_d) == 1 else list(options.pcc_d)
    series = kinematics_figures.kinematics_series(data.kinematics.chain, data.export_q, options.q_samples)
    picture, design_notes = run("pcc_chambers.png", lambda: kinematics_figures.pcc_picture(data.kinematics.chain,
                                                                                      series, d))
    section.pictures.append(picture)
    section.notes.extend(design_notes)
    return section


def _tables_section(data: BuildData) -> tuple[Section, list[Check]]:
    checks = mesh_checks(data.export_summary) + fit_checks(data.fit.summary if data.fit else None)
    checks += volume_mesh_checks(_volume_summary(data))
    checks += output_checks(data.build_dir, data.manifest)
    # no times or run statuses: they differ run to run, and the page is the same bytes for the same build (they are
    # in the run log and LOG)
    stages = [(s["name"], str(s.get("key", ""))[:12], "stale" if s.get("stale") is True else "current")
              for s in data.manifest.get("stages", [])]
    tables = [
        key_figure_table(key_figures(data.manifest)),
        plain_table("Inputs", ("file (as the case names it)", "sha256", "bytes"), input_rows(data.manifest),
                    ("", "hash", "num")),
        plain_table("Software", ("package", "build (manifest.json)", "this report"), software_rows(data.manifest)),
        plain_table("Stages", ("stage", "cache key", "outputs"), stages, ("", "hash", "")),
        *compact_check_tables(checks),
    ]
    notes: list[str] = []  # the build's warnings and notes are the banner's (the manifest's), not repeated here
    return Section("tables", "Figures, inputs, software and checks", notes=notes, tables=tables), checks


def _summary(data: BuildData) -> list[str]:
    blend = data.blend.summary
    q_text = ", ".join(f"{q:g}" for q in data.export_q)
    return [
        f"Case {data.name}: {data.link_count} link(s), {blend['mode']} blend, {blend['frames']} frames, "
        f"export q = {q_text}.",
    ]


def _run_stages(build_dir: Path) -> list[dict[str, Any]]:
    """The stage entries of the build's run log (:data:`~softdesign.pipeline.layout.RUN_LOG`); none when it is
    absent or unreadable (a log: the report does not depend on it)."""
    try:
        stages = json.loads((build_dir / RUN_LOG).read_text(encoding="utf-8")).get("stages", [])
    except (OSError, ValueError, AttributeError):
        return []
    return [s for s in stages if isinstance(s, dict) and isinstance(s.get("name"), str)
            and isinstance(s.get("status"), str) and isinstance(s.get("seconds", 0.0), (int, float))]


def run_log(data: BuildData, seconds: dict[str, float]) -> bytes:
    """:data:`LOG`: the build folder's path, each stage's status and time in its last run (from the build's run log)
    and each report part's time, s."""
    lines = [f"build folder: {Path(os.path.realpath(data.build_dir)).as_posix()}"]
    for stage in _run_stages(Path(data.build_dir)):
        took = f", {stage['seconds']:.3f} s" if "seconds" in stage else ""
        lines.append(f"stage {stage['name']}: {stage['status']}{took} (last run)")
    lines += [f"report part {name}: {value:.3f} s" for name, value in seconds.items()]
    return ("\n".join(lines) + "\n").encode("utf-8")
