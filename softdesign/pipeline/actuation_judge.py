"""The chambers' verdict against the material: one reason per cause (a kind of wall, a bound of extension).

``min_stretch`` has no published source (materials.yaml calls it a rule of thumb): a chamber shortened past it is a
warning, not a reason (issue 41).
"""

from __future__ import annotations

from typing import Any

from softdesign.meshing.chambers.walls import Wall


def judge(walls: list[Wall], extensions: list[dict[str, Any]],
          limits: dict[str, Any] | None) -> tuple[list[str], list[str]]:
    """One reason per cause beyond the material's limits, and one warning per rule of thumb crossed (both empty
    when none, or no material): per kind of wall the thinnest, with the q values where that kind is too thin; per
    bound the worst chamber extension, with how many chambers cross it.  ``min_stretch`` has no published source
    (materials.yaml): crossing it is a warning, not a verdict (issue 41)."""
    if limits is None:
        return [], []
    reasons, warnings, name = [], [], limits["name"]
    if limits["min_wall_mm"] is not None:
        thin: dict[str, list[Wall]] = {}
        for w in walls:
            if w.thickness_mm < limits["min_wall_mm"]:
                thin.setdefault(w.kind, []).append(w)
        for kind, found in thin.items():
            worst = min(found, key=lambda w: w.thickness_mm)
            qs = sorted({w.q for w in found if w.q is not None})
            at_q = f"; too thin at q = {', '.join(f'{q:g}' for q in qs)}" if len(qs) > 1 else ""
            reasons.append(f"{kind} wall {worst.thickness_mm:.3f} mm < min_wall_mm {limits['min_wall_mm']:g} "
                           f"({name}) at {worst.place()}{at_q}")
    for key, bound, worse in (("max", "max_stretch", max), ("min", "min_stretch", min)):
        limit = limits[bound]
        if limit is None:
            continue
        crossed = [e for e in extensions if (e[key] > limit if key == "max" else e[key] < limit)]
        if crossed:
            e = worse(crossed, key=lambda e: e[key])
            sign = ">" if key == "max" else "<"
            text = (f"chamber extension {e[key]:.4f} {sign} {bound} {limit:g} ({name}) at section "
                    f"{e['section']} chamber {e['chamber']}, q={e['q_' + key]:.3f}; {len(crossed)} of "
                    f"{len(extensions)} chambers cross it")
            if bound == "min_stretch":
                warnings.append(text + " (a rule of thumb without a source: a warning, not a verdict)")
            else:
                reasons.append(text)
    return reasons, warnings
