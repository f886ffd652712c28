"""The fitted radius at a path's two ends against the inscribed radius, and why a radius went negative.

A fitted end ring far thinner than the vessel's inscribed sphere cuts a slot
into the end cap: :func:`end_radii` measures the smallest rho of each end
ring (l = 0 and 1) at q = 1 against the ``MaximumInscribedSphereRadius``
there, and :data:`THIN_END_RATIO` is the ratio below which the build warns.
"""

from __future__ import annotations

import numpy as np

from softdesign.fitting.end_prior import EndPrior
from softdesign.fitting.radius_field import FOLD_ANGLES_PER_INTERVAL, RadiusField
from softdesign.types import FloatArray

#: An end ring whose smallest rho is below this fraction of the inscribed radius there is warned about.
THIN_END_RATIO = 0.5


def end_radii(field: RadiusField, reference: tuple[FloatArray, FloatArray] | None) -> dict[str, dict[str, float]]:
    """Per end ("inlet" l = 0, "outlet" l = 1): smallest rho of the ring at q = 1, mm, and against the inscribed radius.

    ``reference`` is (normalized l, inscribed radius mm) or None; without it only ``rho_min_mm`` is given.
    """
    a = np.linspace(0.0, 2.0 * np.pi, FOLD_ANGLES_PER_INTERVAL * field.final[0].angular_intervals, endpoint=False)
    rho = field.evaluate_grid(1.0, np.array([0.0, 1.0]), a).min(axis=1)
    out = {}
    for k, name in enumerate(("inlet", "outlet")):
        out[name] = {"rho_min_mm": float(rho[k])}
        if reference is not None:
            inscribed = float(np.interp(float(k), *reference))
            out[name] |= {"inscribed_mm": inscribed, "ratio": float(rho[k] / inscribed)}
    return out


def thin_end_warnings(ends: dict[str, dict[str, float]]) -> list[str]:
    """One line per end whose ring is thinner than ``THIN_END_RATIO`` of the inscribed radius."""
    return [
        f"the {name} ring's smallest radius is {e['rho_min_mm']:.3f} mm, {e['ratio']:.2f} of the inscribed radius "
        f"{e['inscribed_mm']:.3f} mm (below {THIN_END_RATIO:g}): the wall points there are few or one-sided; "
        "check the surface near that end"
        for name, e in ends.items() if "ratio" in e and e["ratio"] < THIN_END_RATIO
    ]


def negative_radius_cause(prior: EndPrior | None, length_mm: float, l_min: float) -> str:
    """Why rho went to zero or below at normalized ``l_min``: the end it is near and what the wall showed there."""
    s = l_min * length_mm
    end, to_end = ("inlet", s) if l_min <= 0.5 else ("outlet", length_mm - s)
    unseen = {} if prior is None else prior.ends.get(end, {})
    seen = (
        f"the wall there is not seen all the way round over the last {unseen['unseen_mm']:.1f} mm "
        f"({unseen['empty_cells']:.0f} empty cells held at the inscribed radius)"
        if unseen else "the wall is seen all round there"
    )
    return (
        f"the smallest radius is {to_end:.1f} mm from the {end} ({s:.1f} mm along the path) and {seen}: "
        "the wall points near that end lean inwards (a tilted cap's rim, another branch's wall), so the fit "
        "follows them; check the surface near that end, or set final.inlet / final.reverse so the path starts "
        "at an open end"
    )
