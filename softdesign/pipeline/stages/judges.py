"""What each judging stage says of the design (:class:`~softdesign.pipeline.notices.Judgement`), from its summary.

The stages' summaries keep their figures and reasons as before; these
functions hand them to the one verdict (the manifest's ``verdict``), so that no
stage prints a verdict of its own.  Reasons say why the design cannot be
made or cannot reach the vessel; margins say by how much it can.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from softdesign.pipeline.notices import Judgement, Notice


def material_judgement(summary: dict[str, Any] | None, what: str = "") -> Judgement | None:
    """The skin's (feasibility), the chambers' (actuation) or the 3D (volume mesh) judgement against the material.

    ``summary`` has ``material`` (None: not judged), ``feasible`` and ``reasons``; ``what`` prefixes each reason
    (``chambers``).  None for a stage that did not run its part (no chambers, no volume mesh).
    """
    if not summary or "reasons" not in summary:
        return None
    material = summary.get("material")
    if material is None:
        return Judgement(judged=False)
    reasons = tuple(f"{what}: {r}" if what else r for r in summary["reasons"])
    return Judgement(judged=True, reasons=reasons, material=str(material.get("name", "")))


def actuation_judgement(summary: dict[str, Any]) -> Judgement | None:
    """The chambers' judgement against the material, with the single-supply device's line as a margin.

    The rod model's refusals are among ``summary["reasons"]`` already; when none, the device's line ("one
    pressure of P* kPa bends it into the vessel within X mm (rod model), walls >= W mm, thread at T % of its
    limit") says by how much it can, judged or not.
    """
    judgement = material_judgement(summary, "chambers")
    line = summary.get("verdict_line")
    if judgement is None or not line or judgement.reasons:
        return judgement
    return replace(judgement, margins=(*judgement.margins, line.removeprefix("device: ")))


def rule_notices(stage: str, summary: dict[str, Any] | None) -> list[Notice]:
    """A warning per rule of thumb a stage's figures cross (``summary["warnings"]``: margins without a published
    source, such as ``min_stretch``; never a reason of the verdict)."""
    return [Notice(stage, "rule_of_thumb", "", text) for text in (summary or {}).get("warnings", [])]


def design_judgement(document: dict[str, Any] | None) -> Judgement | None:
    """The composed design's margin to the vessel (its miss of the tolerance is a warning, not a reason)."""
    if document is None:
        return None
    margin = (f"the composed design is within {document['chain_max_deviation_mm']:.2g} mm of the vessel's "
              f"centerline, tip {document['tip_error_mm']:.2g} mm off")
    return Judgement(judged=False, margins=(margin,))


def mould_judgement(summary: dict[str, Any]) -> Judgement | None:
    """The mould's checks: a reason when one fails (the part cannot be cast as drawn), else a margin."""
    if not summary.get("requested"):
        return None
    failed = [name for name, ok in _mould_checks(summary) if not ok]
    if failed:
        return Judgement(judged=False, reasons=(f"the mould cannot be used as drawn: {', '.join(failed)} "
                                                "(see the mould section of the report)",))
    return Judgement(judged=False, margins=("the mould checks pass: the cavity matches the body, the parts do not "
                                            "overlap, every part pulls free",))


def _mould_checks(summary: dict[str, Any]) -> list[tuple[str, bool]]:
    """``(what failed, passed)`` of each of the mould's checks."""
    checks = [("the cavity differs from the body", bool(summary["cavity"]["ok"])),
              ("the parts overlap", bool(summary["disjoint"]["ok"]))]
    checks += [(f"the {part} does not pull free", bool(p["ok"])) for part, p in summary.get("pull", {}).items()]
    return checks


def simulate_notices(summary: dict[str, Any] | None) -> list[Notice]:
    """A warning per finite-element solve that did not converge (its figures are then not the section's)."""
    if not summary:
        return []
    return [Notice("simulate", "not_converged", f"section {s['section']}, q = {s['q']:g}",
                   f"section {s['section']} at q = {s['q']:g}: the finite-element search did not converge "
                   f"({s['target']['how']}); its pressures and stresses are the last trial's")
            for s in summary.get("solves", []) if not s["target"]["converged"]]
