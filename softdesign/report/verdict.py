"""The report's first screen: the build's one verdict, as the manifest records it, then why.

The verdict is computed once, when the build writes its manifest
(:func:`softdesign.pipeline.notices.verdict_record`: every judging stage's
reasons and margins); the terminal prints the same record, so the two cannot
disagree.  The checks' tally comes after this box and the warnings, folded
(:func:`checks_html`), never directly under the verdict.
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from typing import Any

from softdesign.pipeline.notices import FEASIBLE, INFEASIBLE, NOT_JUDGED
from softdesign.report.tables import Check

#: The headline of a manifest written before builds recorded their verdict.
OLDER_BUILD = "not judged: this build was made before builds recorded their verdict; run `softdesign build` again"


@dataclass(frozen=True)
class Verdict:
    """``status``: the verdict's word; ``headline`` one line; ``reasons`` (cannot be made or reached), ``margins``."""

    status: str
    headline: str
    reasons: tuple[str, ...]
    margins: tuple[str, ...]


def build_verdict(manifest: dict[str, Any]) -> Verdict:
    """The manifest's ``verdict`` (the one the terminal printed)."""
    record = manifest.get("verdict")
    if not isinstance(record, dict) or record.get("status") not in (FEASIBLE, INFEASIBLE, NOT_JUDGED):
        return Verdict(NOT_JUDGED, OLDER_BUILD, (), ())
    return Verdict(record["status"], record["headline"], tuple(record.get("reasons", [])),
                   tuple(record.get("margins", [])))


def verdict_html(verdict: Verdict) -> str:
    """The verdict box: the headline, then each reason, then each margin."""
    css = {FEASIBLE: "verdict ok", INFEASIBLE: "verdict bad", NOT_JUDGED: "verdict open"}[verdict.status]
    items = "".join(f"<li>{escape(r)}</li>" for r in verdict.reasons)
    items += "".join(f'<li class="margin">{escape(m)}</li>' for m in verdict.margins)
    more = f"<ul>{items}</ul>" if items else ""
    return (f'<div class="{css}" id="verdict" data-status="{escape(verdict.status, quote=True)}">'
            f'<p class="headline">Verdict: {escape(verdict.headline)}</p>{more}</div>\n')


def checks_html(checks: list[Check]) -> str:
    """The checks' tally, folded below the verdict and the warnings; open, listing the failures, when any fails."""
    passed = sum(c.passed for c in checks)
    failed = [c for c in checks if not c.passed]
    items = "".join(f"<li>{escape(c.subject)}: {escape(c.name)}</li>" for c in failed)
    body = (f"<ul>{items}</ul>" if failed else "") + '<p>Every check is listed in the tables section.</p>'
    return (f'<details class="tally" id="checks"{" open" if failed else ""}><summary>Checks: {passed} of '
            f"{len(checks)} passed</summary>{body}</details>\n")
