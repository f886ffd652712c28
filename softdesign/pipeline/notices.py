"""One record of what a build warns about, and one verdict: the terminal, the manifest and the report read these.

Every stage says what it warns about through :attr:`Stage.warnings
<softdesign.pipeline.stage.Stage.warnings>` (a list of :class:`Notice`: its
stage, a short code, the place and the text), and what it judges through
:attr:`Stage.judge <softdesign.pipeline.stage.Stage.judge>` (a
:class:`Judgement`: ``reasons`` the design cannot be made or cannot reach
the vessel, ``margins`` the figures that say by how much it can).  The
runner collects both once, in stage order, into the manifest's
``warnings`` and ``verdict``; the command line prints the manifest's lists,
and the report shows them.  Nothing else prints a warning of a build, so the
three cannot disagree.

A stage that adds a judgement (the rod model's "one pressure of P* kPa bends
it into the vessel within X mm", or why not) returns it from its ``judge``;
a rule of thumb without a cited source is a :class:`Notice`, not a reason.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass
from typing import Any

#: The two kinds of notice: a warning must be read before trusting the design; a note says what was done.
WARNING, NOTE = "warning", "note"


@dataclass(frozen=True)
class Notice:
    """One warning or note of a build.

    Attributes
    ----------
    stage : the stage that raised it (``fit``)
    code : a short stable name of the kind (``centerline_stray``), for tests and tools; never shown alone
    place : where, in an engineer's words (``link 2``, ``outlet``); "" for the whole body
    text : the sentence the user reads: what, where, by how much, and what to do
    kind : :data:`WARNING` or :data:`NOTE`
    """

    stage: str
    code: str
    place: str
    text: str
    kind: str = WARNING


@dataclass(frozen=True)
class Judgement:
    """What one stage says about the design.

    Attributes
    ----------
    judged : the stage judged the design against the case's material (else its limits are unknown)
    reasons : why the design cannot be made or cannot reach the vessel, each a whole sentence with its place and
        figures, starting with what it is about in an engineer's words (``chambers: ...``), never a stage's name
    margins : by how much it can, each a sentence with its figures
    material : the material judged against ("" when none)
    """

    judged: bool
    reasons: tuple[str, ...] = ()
    margins: tuple[str, ...] = ()
    material: str = ""


#: The verdict's words: the same in the terminal, the manifest and the report.
FEASIBLE, INFEASIBLE, NOT_JUDGED = "feasible", "NOT feasible", "not judged"


def notices_record(notices: Iterable[Notice]) -> list[dict[str, str]]:
    """The manifest's ``warnings``: each notice once (the first of equal ones), in the order given."""
    seen: set[Notice] = set()
    record = []
    for notice in notices:
        if notice not in seen:
            seen.add(notice)
            record.append(asdict(notice))
    return record


def verdict_record(judgements: Iterable[tuple[str, Judgement]]) -> dict[str, Any]:
    """The manifest's ``verdict`` from each stage's judgement (``(stage, judgement)`` in stage order).

    ``feasible`` is False when any stage gives a reason, True when none does and some stage judged the design
    against a material, and None (not judged) otherwise.  ``status`` is the verdict's word and ``headline`` the
    line every output leads with.
    """
    reasons: list[str] = []
    margins: list[str] = []
    materials: list[str] = []
    judged = False
    for _stage, judgement in judgements:
        reasons += [r for r in judgement.reasons if r not in reasons]
        margins += [m for m in judgement.margins if m not in margins]
        judged = judged or judgement.judged
        if judgement.material and judgement.material not in materials:
            materials.append(judgement.material)
    feasible = False if reasons else (True if judged else None)
    status = INFEASIBLE if feasible is False else (FEASIBLE if feasible else NOT_JUDGED)
    return {"feasible": feasible, "status": status, "material": ", ".join(materials),
            "headline": _headline(status, ", ".join(materials), reasons), "reasons": reasons, "margins": margins}


def _headline(status: str, material: str, reasons: list[str]) -> str:
    """The verdict's first line."""
    if status == NOT_JUDGED:
        return ("not judged: the case names no material (add `material: {name: ecoflex-00-30}`, or another preset "
                "from `softdesign materials`, to judge the design against its limits)")
    against = f" for {material}" if material else ""
    if status == FEASIBLE:
        return f"feasible{against}"
    return f"NOT feasible{against}: {len(reasons)} reason(s)"


def verdict_lines(verdict: dict[str, Any]) -> list[str]:
    """The verdict as the terminal prints it: the headline, then each reason and margin indented."""
    lines = [f"verdict: {verdict['headline']}"]
    lines += [f"  - {r}" for r in verdict.get("reasons", [])]
    lines += [f"  + {m}" for m in verdict.get("margins", [])]
    return lines


def warning_lines(record: list[dict[str, Any]]) -> list[str]:
    """The manifest's warnings (and notes) as the terminal prints them, each once; none when there are none."""
    warnings = [w for w in record if w.get("kind", WARNING) == WARNING]
    notes = [w for w in record if w.get("kind") == NOTE]
    lines = [f"note: {w['stage']}: {w['text']}" for w in notes]
    if warnings:
        lines.append(f"{len(warnings)} warning(s):")
        lines += [f"  warning: {w['stage']}: {w['text']}" for w in warnings]
    return lines
