"""The hoop thread's quadrature on a wall face, swapped for a comparison: the solver's (the law at the centroid,
hourglass control on six points, :data:`softdesign.mechanics.reinforcement.FIBRE_WEIGHTS`), the centroid alone, or
the law at the pressure's six points alone (the module's docstring: "Integration").  For tests and studies only:
the solver's rule is the module's, and this swaps its four constants, which
:func:`~softdesign.mechanics.reinforcement.hoop_membrane` reads when it builds the fibres."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from unittest import mock

import numpy as np

from softdesign.mechanics import reinforcement
from softdesign.mechanics.quadratic_pressure import TRI_POINTS, TRI_WEIGHTS, triangle_shapes

#: The rules by name: "solver" is the module's own.
RULES = ("solver", "one-point", "six-point")


@contextlib.contextmanager
def fibre_rule(rule: str) -> Iterator[None]:
    """The thread's fibres integrated by ``rule`` (one of :data:`RULES`) while inside."""
    if rule == "solver":
        yield
        return
    if rule == "one-point":
        points, weights = np.array([[1.0 / 3.0, 1.0 / 3.0]]), np.array([0.5])
    elif rule == "six-point":
        points, weights = TRI_POINTS, TRI_WEIGHTS
    else:
        raise ValueError(f"fibre rule must be one of {', '.join(RULES)}, got {rule!r}")
    _, dxi, deta = triangle_shapes(points)
    with mock.patch.multiple(reinforcement, FIBRE_DXI=dxi, FIBRE_DETA=deta, FIBRE_WEIGHTS=weights,
                             FIBRE_ANCHORED=False):
        yield


def six_point_share(rule: str) -> float:
    """The share of the thread's energy on the six points under ``rule`` (the solver's is
    :data:`~softdesign.mechanics.reinforcement.FIBRE_STABILISATION`)."""
    if rule not in RULES:
        raise ValueError(f"fibre rule must be one of {', '.join(RULES)}, got {rule!r}")
    return {"solver": reinforcement.FIBRE_STABILISATION, "one-point": 0.0, "six-point": 1.0}[rule]
