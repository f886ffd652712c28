"""rho(q), d rho / dl and d rho / da of a radius field on a grid, a block of rows at a time.

The skin's metric (:func:`softdesign.fitting.strain.skin_metric`) and the
folding check (:func:`softdesign.fitting.radius_field.fold_margin`) walk
their grids in blocks of about ``BLOCK_POINTS`` points: the same numbers as
:meth:`RadiusField.evaluate_grid <softdesign.fitting.radius_field.RadiusField.evaluate_grid>`
on the whole grid, since every value is computed point by point.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.types import FloatArray, IntArray


class LinkBases(Protocol):
    """What :class:`SlopeRows` reads of a radius field: each link's two splines and the bases along l.

    :class:`~softdesign.fitting.radius_field.RadiusField` is one; naming only this keeps the field's
    module above this one (the field imports the rows, never the other way).
    """

    @property
    def final(self) -> Sequence[RadiusSpline]: ...

    @property
    def initial(self) -> Sequence[RadiusSpline]: ...

    def along_bases(self, l: npt.ArrayLike, slopes: bool = True
                    ) -> tuple[tuple[int, IntArray, IntArray, FloatArray, FloatArray], ...]: ...

#: Grid points evaluated at a time by the callers of :class:`SlopeRows` (the skin's metric and
#: stretches, the folding check): a block's dozen temporaries (16384 float64 each, 128 kB) stay in a
#: core's cache, where a whole fine grid's (5.8 MB each on the 1M-triangle benchmark case) went to
#: memory and back between every two operations.  Every value is computed point by point, so the
#: blocks change no bit.
BLOCK_POINTS = 16384


def row_blocks(rows: int, points_per_row: int) -> list[slice]:
    """The blocks of whole rows of about ``BLOCK_POINTS`` points (at least one row each), in order; none for no row."""
    size = max(1, BLOCK_POINTS // max(1, points_per_row))
    return [slice(start, start + size) for start in range(0, rows, size)]


class SlopeRows:
    """rho, rho_l and rho_a of one q on the grid l (p,) x a (m,), evaluated for a block of its rows at a time.

    Each value is added up as :func:`~softdesign.fitting.bspline_surface.grid_from_local` adds it:
    around first, then along, in ascending basis index, from zero; a block of rows small enough to
    stay in the processor's cache costs far less than the whole grid's arrays at once.  With
    ``slopes=False`` only rho is prepared (:meth:`values`); with ``angular=False`` rho and rho_l
    (:meth:`along`), for a caller that takes the a-derivative otherwise (the offset surfaces of
    :mod:`softdesign.meshing.body.wall`).
    """

    def __init__(self, field: LinkBases, q: float, l: npt.ArrayLike, a: npt.ArrayLike, slopes: bool = True,
                 angular: bool = True) -> None:
        l = np.asarray(l, float).reshape(-1)
        self.shape = (len(l), int(np.size(a)))
        self.slopes, self.angular = slopes, slopes and angular
        angles = np.ascontiguousarray(a, float).reshape(-1)
        around: dict[tuple[int, int], tuple[IntArray, FloatArray]] = {}
        #: per link present: its rows (ascending), local basis indices along l, values, slopes (or values),
        #: and the coefficients summed over the periodic basis (n, m) and over its derivative (or the same)
        self._links: list[tuple[IntArray, IntArray, FloatArray, FloatArray, FloatArray, FloatArray]] = []
        for j, rows, index, values, slopes_l in field.along_bases(l, slopes):
            f, i = field.final[j], field.initial[j]
            m = f.angular_intervals
            for da in (0, 1) if self.angular else (0,):
                if (m, da) not in around:
                    around[m, da] = _sorted_around(m, angles, da)
            coefficients = (1.0 - q) * i.coefficients + q * f.coefficients  # as link_spline blends them
            inner = _around_sum(coefficients, around[m, 0])
            inner_a = _around_sum(coefficients, around[m, 1]) if self.angular else inner
            self._links.append((rows, index, values, slopes_l, inner, inner_a))

    def __call__(self, start: int, stop: int) -> tuple[FloatArray, FloatArray, FloatArray]:
        """rho, rho_l and rho_a (stop - start, m) on rows ``start:stop`` of the grid."""
        if not self.angular:
            raise ValueError("SlopeRows: prepared without slopes (slopes=False) or without rho_a (angular=False); "
                             "use values() or along()")
        return self._rows(start, stop, True, True)

    def along(self, start: int, stop: int) -> tuple[FloatArray, FloatArray]:
        """rho and rho_l (stop - start, m) on rows ``start:stop`` of the grid."""
        if not self.slopes:
            raise ValueError("SlopeRows: prepared without slopes (slopes=False); use values()")
        rho, rho_l, _ = self._rows(start, stop, True, False)
        return rho, rho_l

    def values(self, start: int, stop: int) -> FloatArray:
        """rho (stop - start, m) on rows ``start:stop`` of the grid."""
        return self._rows(start, stop, False, False)[0]

    def _rows(self, start: int, stop: int, slopes: bool, angular: bool
              ) -> tuple[FloatArray, FloatArray, FloatArray]:
        shape = (max(0, min(stop, self.shape[0]) - start), self.shape[1])
        # what is not asked for only stands for rho (nothing is added into it)
        rho = np.zeros(shape)
        rho_l = np.zeros(shape) if slopes else rho
        rho_a = np.zeros(shape) if angular else rho
        for rows, index, values, slopes_l, inner, inner_a in self._links:
            lo, hi = np.searchsorted(rows, (start, stop))
            if lo == hi:
                continue
            at = rows[lo:hi] - start
            contiguous = at[-1] - at[0] == hi - lo - 1  # l ascending: add up in place, in the block's rows
            if contiguous:
                block = slice(int(at[0]), int(at[-1]) + 1)
                value, value_l, value_a = rho[block], rho_l[block], rho_a[block]
            else:
                value, value_l, value_a = (np.zeros((hi - lo, shape[1])) for _ in range(3))
            for r in range(index.shape[1]):
                near = inner[index[lo:hi, r]]
                value += values[lo:hi, r, None] * near
                if slopes:
                    value_l += slopes_l[lo:hi, r, None] * near
                if angular:
                    value_a += values[lo:hi, r, None] * inner_a[index[lo:hi, r]]
            if not contiguous:
                rho[at] = value
                if slopes:
                    rho_l[at] = value_l
                if angular:
                    rho_a[at] = value_a
        return rho, rho_l, rho_a


#: The angular bases :func:`_sorted_around` made last, by (intervals, angles' bytes, derivative), least recently
#: used first: every q of a grid asks for the same ones, each link for the same (a few kB each).
_AROUND: dict[tuple[int, bytes, int], tuple[IntArray, FloatArray]] = {}
#: How many :data:`_AROUND` keeps.
AROUND_CACHE = 8


def _sorted_around(intervals: int, angles: FloatArray, deriv: int) -> tuple[IntArray, FloatArray]:
    """The periodic basis at ``angles`` (m,) (:func:`~softdesign.fitting.bspline_basis.periodic_local`), each row
    in ascending basis index (the order :func:`_around_sum` adds in), read-only; made once for the last few asked.
    """
    key = (int(intervals), angles.tobytes(), int(deriv))
    found = _AROUND.pop(key, None)  # put back last: the dict runs from least to most recently used
    if found is None:
        rows, values = bb.periodic_local(intervals, angles, deriv)
        order = np.argsort(rows, axis=1, kind="stable")
        found = np.take_along_axis(rows, order, axis=1), np.take_along_axis(values, order, axis=1)
        for array in found:
            array.setflags(write=False)
    _AROUND[key] = found
    while len(_AROUND) > AROUND_CACHE:
        _AROUND.pop(next(iter(_AROUND)))
    return found


def _around_sum(coefficients: FloatArray, around: tuple[IntArray, FloatArray]) -> FloatArray:
    """``sum_s P_s(a_m) C[:, j_ms]`` (n, m), in ascending basis index from zero (as grid_from_local); ``around`` is
    :func:`_sorted_around`'s, each row's indices ascending."""
    rows_a, values_a = around
    inner = np.zeros((coefficients.shape[0], rows_a.shape[0]))
    for s in range(rows_a.shape[1]):
        inner += coefficients[:, rows_a[:, s]] * values_a[:, s]
    return inner
