"""The feasibility verdict: every figure against the material's limits, one reason per cause.

A limit crossed at several q (at q = 0.5 and 1, and again by the search over
the whole morph, at the same place) is one cause, not three warnings: its
reason names the worst value found, where it is (link, mm from the base along
the body at that q, angle around it) and every q at which the limit is crossed.
Places are in mm from the base when the summary has them (``arc_mm``, written
since this module exists); an older build's summary gives normalized l only,
and its reasons say ``l = ...``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: (figure key in a per-q row, its place key in the row's ``where``, limit key, relation, what it is)
PER_Q_LIMITS = (
    ("stretch_max", "stretch_max", "max_stretch", ">", "skin stretch"),
    ("stretch_min", "stretch_min", "min_stretch", "<", "skin stretch"),
    ("wall_min_mm", "wall_min", "min_wall_mm", "<", "wall (mm)"),
)


@dataclass(frozen=True)
class Violation:
    """One figure beyond its limit, at one q (or at the morph's extreme)."""

    what: str
    value: float
    relation: str
    limit_name: str
    limit: float
    q: float
    where: dict[str, Any]
    over_morph: bool = False

    @property
    def cause(self) -> tuple[str, str]:
        return self.what, self.limit_name

    def worse_than(self, other: Violation) -> bool:
        return self.value > other.value if self.relation == ">" else self.value < other.value


def place_text(where: dict[str, Any] | None) -> str:
    """``link 0, 2.9 mm from the base, angle 61 deg`` (``l = 0.0386`` for an older summary without arc_mm)."""
    if not where:
        return "an unrecorded place"
    parts = [f"link {where['link']}"] if "link" in where else []
    parts.append(f"{where['arc_mm']:.1f} mm from the base" if "arc_mm" in where else f"l = {where['l']:.4f}")
    if "angle_deg" in where:
        parts.append(f"angle {where['angle_deg']:.0f} deg")
    return ", ".join(parts)


def violations(summary: dict[str, Any], limits: dict[str, Any]) -> list[Violation]:
    """Every figure of ``summary`` (per export q, then over the morph) beyond a limit of ``limits``."""
    found = []
    for row in summary["per_q"]:
        for key, place, limit_name, relation, what in PER_Q_LIMITS:
            limit, value = limits.get(limit_name), row.get(key)
            if limit is None or value is None or not _beyond(value, relation, limit):
                continue
            found.append(Violation(what, value, relation, limit_name, limit, row["q"], row["where"].get(place, {})))
        port = row.get("port_wall_mm")
        if limits.get("min_wall_mm") is not None and port is not None and port < limits["min_wall_mm"]:
            found.append(Violation("port wall (mm)", port, "<", "min_wall_mm", limits["min_wall_mm"], row["q"],
                                   row.get("port_where", {})))
    for key, limit_name, relation in (("stretch_max", "max_stretch", ">"), ("stretch_min", "min_stretch", "<")):
        m = summary["morph"][key]
        limit = limits.get(limit_name)
        if limit is not None and _beyond(m["value"], relation, limit):
            found.append(Violation("skin stretch", m["value"], relation, limit_name, limit, m["q"], m["where"],
                                   over_morph=True))
    return found


def causes(found: list[Violation], material: str) -> list[dict[str, Any]]:
    """One entry per cause, in the order first found: the worst violation, its place, and every q it holds at."""
    groups: dict[tuple[str, str], list[Violation]] = {}
    for v in found:
        groups.setdefault(v.cause, []).append(v)
    out = []
    for group in groups.values():
        worst = group[0]
        for v in group[1:]:
            if v.worse_than(worst):
                worst = v
        export_q = sorted({v.q for v in group if not v.over_morph})
        morph_q = sorted({v.q for v in group if v.over_morph} - set(export_q))
        out.append({
            "what": worst.what, "value": worst.value, "relation": worst.relation, "limit_name": worst.limit_name,
            "limit": worst.limit, "material": material, "q": worst.q, "where": worst.where,
            "export_q": export_q, "morph_q": morph_q,
        })
    return out


def cause_text(cause: dict[str, Any]) -> str:
    """``skin stretch 0.1095 < min_stretch 0.7 (ecoflex-00-30) at link 0, 2.9 mm from the base, angle 61 deg
    (q = 1); crossed at export q = 0.5, 1``."""
    what = cause["what"].replace(" (mm)", "")
    unit = " mm" if cause["what"].endswith("(mm)") else ""
    text = (f"{what} {cause['value']:.4g}{unit} {cause['relation']} {cause['limit_name']} {cause['limit']:g}"
            f"{unit} ({cause['material']}) at {place_text(cause['where'])} (q = {cause['q']:.3g})")
    crossed = [f"export q = {', '.join(f'{q:g}' for q in cause['export_q'])}"] if cause["export_q"] else []
    if cause["morph_q"]:
        crossed.append(f"over the morph at q = {', '.join(f'{q:.3f}' for q in cause['morph_q'])}")
    return text + ("; crossed at " + " and ".join(crossed) if crossed else "")


#: Limits with no published source (materials.yaml: ``min_stretch`` is a rule of thumb): crossing one is a
#: warning, not a verdict (issue 41).
WARNING_ONLY = ("min_stretch",)


def judge(summary: dict[str, Any], limits: dict[str, Any] | None) -> tuple[bool | None, list[str], list[dict]]:
    """The verdict, one reason per cause, and the causes themselves (JSON-ready); (None, [], []) without limits.

    A cause of a :data:`WARNING_ONLY` limit is kept in the causes but neither decides the verdict nor is a reason
    (:func:`warnings_of` words it)."""
    if limits is None:
        return None, [], []
    found = causes(violations(summary, limits), limits["name"])
    binding = [c for c in found if c["limit_name"] not in WARNING_ONLY]
    return not binding, [cause_text(c) for c in binding], found


def warnings_of(found: list[dict[str, Any]]) -> list[str]:
    """The causes of limits without a source, as warnings."""
    return [cause_text(c) + " (a rule of thumb without a source: a warning, not a verdict)" for c in found
            if c["limit_name"] in WARNING_ONLY]


def _beyond(value: float, relation: str, limit: float) -> bool:
    return value > limit if relation == ">" else value < limit
