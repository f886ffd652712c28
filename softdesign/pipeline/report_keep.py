"""A build that changes no output keeps the report of the build it replaces; one that does says the report is gone.

The report (``report/``) is drawn from a build's outputs.  When a rebuild
gives the same outputs (every path and hash the manifest lists, and the same
resolved case), the page still describes the folder exactly, so its files are
carried into the new folder as the kept stages' are.  When any output
changed, the old page would describe a build that is no longer there: it goes
with the old folder, and the build says so and how to make it again (drawing
a new one would add the report's time to every rebuild of a cohort; ``build
--report`` does that when asked).
"""

from __future__ import annotations

import json
from typing import Any

from softdesign.pipeline.layout import MANIFEST, REPORT_DIR
from softdesign.pipeline.owned import legacy_report_files, report_marker_files
from softdesign.pipeline.store import Staging, sha256_file


def _outputs(manifest: dict[str, Any]) -> tuple[dict[Any, Any], Any]:
    listed = manifest.get("outputs", []) + manifest.get("records", [])
    return {e.get("path"): e.get("sha256") for e in listed if isinstance(e, dict)}, manifest.get("case")


def carry_report(staging: Staging, manifest: dict[str, Any]) -> str | None:
    """Keep the current folder's report in ``staging`` when ``manifest`` lists the same outputs; else a note.

    Returns the line to tell the user (None when there is no report, or it was kept).
    """
    folder = staging.target
    report = folder / REPORT_DIR
    if report.is_symlink() or not report.is_dir():
        return None
    names = report_marker_files(report) or legacy_report_files(folder)
    if not names:
        return None  # not a report of softdesign's: the owned-folder check has refused the build already
    try:
        before = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        before = {}
    if isinstance(before, dict) and _outputs(before) == _outputs(manifest):
        for name in names:
            relative = f"{REPORT_DIR}/{name}"
            staging.keep(relative, sha256_file(folder / relative))
        return None
    return (f"report/ removed: it showed the previous build's outputs, which changed; make it again with "
            f"softdesign report {staging.build_dir} (or build with --report)")
