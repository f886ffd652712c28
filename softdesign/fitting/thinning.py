"""An even subset of wall points for the surface's least squares, when there are more than it needs.

The points are ordered cell by cell (a cell: one knot interval along l and one
angular knot interval around, the spline's own patches), by l inside a cell,
and ``count`` evenly spaced ranks of that order are kept.  So every cell keeps
its share of the points to within one, spread along its length, and the same
points give the same subset (no random draw).
"""

from __future__ import annotations

import numpy as np

from softdesign.fitting.projection import PolarPoints


def even_subset(polar: PolarPoints, along: int, around: int, count: int) -> np.ndarray:
    """Sorted indices (min(count, n),) of an even subset of the n points (see the module notes).

    Parameters
    ----------
    polar : the points' (l, angle), l normalized in [0, 1], angle in rad
    along, around : knot intervals along l and around (cells along x around)
    count : the most points kept (>= 1)
    """
    n = len(polar)
    if n <= count:
        return np.arange(n)
    row = np.minimum((np.asarray(polar.l) * along).astype(np.int64), along - 1)
    turn = np.mod(np.asarray(polar.angle), 2.0 * np.pi) / (2.0 * np.pi)
    column = np.minimum((turn * around).astype(np.int64), around - 1)
    order = np.lexsort((polar.l, row * around + column))
    ranks = ((np.arange(count) + 0.5) * (n / count)).astype(np.int64)
    return np.sort(order[ranks])
