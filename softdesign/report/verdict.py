"""The report's first screen: one line that says whether the design can be made and used, then why.

The verdict is the feasibility stage's (``metrics.feasibility.feasible``,
judged against the case's ``material:``); the reasons are its causes, one per
cause, each with its place in mm from the base.  What else a device engineer
must know before trusting the design follows in the same box: how far the
composed design is from the vessel (when the build has a design), whether the
mould checks pass (when it has a mould), and any fit that holds a long
stretch of the body away from its wall.  Without a material the design is
"not judged", and the line says how to judge it.  The checks' tally comes
after this box, never above it.
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from typing import Any

from softdesign.report.tables import resolve_or


@dataclass(frozen=True)
class Verdict:
    """``status``: "feasible", "infeasible" or "not judged"; ``headline`` one line; ``reasons`` and ``notes``."""

    status: str
    headline: str
    reasons: tuple[str, ...]
    notes: tuple[str, ...]


def build_verdict(manifest: dict[str, Any]) -> Verdict:
    """The verdict of a build's manifest (see the module notes): the skin's (feasibility) and, with chambers, the
    chambers' walls and extensions (actuation) against the material."""
    block = resolve_or(manifest, "/metrics/feasibility", None)
    feasible = block.get("feasible") if isinstance(block, dict) else None
    actuation = resolve_or(manifest, "/metrics/actuation", None)
    chambers_ok = actuation.get("feasible") if isinstance(actuation, dict) else None
    extras = _extras(manifest)
    # the fit's own warnings (a long stretch held at the inscribed radius, wall far from the body): the figures of
    # the design hold only where the body matches the vessel
    fit_notes = tuple(f"fit: {w}" for w in resolve_or(manifest, "/metrics/fit/warnings", []))
    if feasible is None:
        headline = "Not judged: the case declares no material (add material: {name: ecoflex-00-30}, or another "
        headline += "preset, to judge the design against its limits)"
        return Verdict("not judged", headline, (), (*extras, *fit_notes))
    material = (block.get("material") or {}).get("name", "its material")
    reasons = tuple(block.get("reasons", []))
    if chambers_ok is False:  # the chambers' walls and extensions (the actuation stage) are judged too
        feasible = False
        reasons += tuple(f"chambers: {r}" for r in actuation.get("reasons", []))
    if feasible:
        caveat = ["but the fit does not match the vessel everywhere (below)"] if fit_notes else []
        return Verdict("feasible", "; ".join([f"Feasible for {material}", *extras, *caveat]), (), fit_notes)
    first = reasons[0] if reasons else "a limit of the material is crossed"
    return Verdict("infeasible", f"NOT feasible: {first}", reasons[1:], (*extras, *fit_notes))


def _extras(manifest: dict[str, Any]) -> list[str]:
    """What else the first screen says, each when the build has it."""
    extras = []
    chain = resolve_or(manifest, "/metrics/design/chain_max_deviation_mm", None)
    if isinstance(chain, (int, float)):
        tip = resolve_or(manifest, "/metrics/design/tip_error_mm", None)
        tip_text = f", tip {tip:.2g} mm" if isinstance(tip, (int, float)) else ""
        extras.append(f"the composed design is within {chain:.2g} mm of the vessel{tip_text}")
    device = resolve_or(manifest, "/metrics/actuation/verdict_line", None)
    if isinstance(device, str):  # the single-supply device: one pressure bends it into the vessel, or why not
        extras.append(device.removeprefix("device: "))
    mould = resolve_or(manifest, "/metrics/mould", None)
    if isinstance(mould, dict) and mould.get("requested"):
        parts = [mould.get("cavity", {}), mould.get("disjoint", {}), *mould.get("pull", {}).values()]
        ok = all(isinstance(p, dict) and p.get("ok") for p in parts)
        extras.append("the mould checks pass (cavity, disjoint parts, every part pulls free)" if ok
                      else "the mould checks FAIL (see the mould section)")
    return extras


def verdict_html(verdict: Verdict, tally: str) -> str:
    """The verdict box, then the checks' tally line (``tally``)."""
    css = {"feasible": "verdict ok", "infeasible": "verdict bad", "not judged": "verdict open"}[verdict.status]
    items = "".join(f"<li>{escape(r)}</li>" for r in (*verdict.reasons, *verdict.notes))
    more = f"<ul>{items}</ul>" if items else ""
    return (f'<div class="{css}" id="verdict" data-status="{escape(verdict.status, quote=True)}">'
            f'<p class="headline">{escape(verdict.headline)}</p>{more}</div>\n<p class="tally">{escape(tally)}</p>\n')
