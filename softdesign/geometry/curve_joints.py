"""Joints of a resampled curve: link breaks where the curvature jumps, kept sharp.

Seed 003's sections meet with a jump of the curvature vector; a spline through
samples on both sides rounds that corner (by ~0.1 h dk of tangent).  A break
is a joint when the polyline has a vertex there and the break is a sample of
the resampling grid: :func:`softdesign.geometry.curves.smooth_curve_from_polyline`
then smooths and resamples each piece between joints on its own, and
:func:`pieces_spline` joins the pieces' interpolants with a knot of full
multiplicity at each joint, so no smoothing crosses it.

The vertex is found along the spline interpolating every vertex of the
path, whatever the smoothing: a smoothing spline through the whole path
rounds the corner and moves the vertex's arc length by about the smoothing
(5e-3 to 8e-2 mm on seed 003's arcs at 0.01 to 0.1 mm), and a tolerance that
wide would also cut smooth, noisy VMTK paths at a break that happens to lie
near a vertex, and kink them there.  Each piece is then smoothed on its own
with the case's smoothing, pinned at its joints (both pieces pass through the
joint's vertex).

What a piece keeps is the smoothing's: a constant-curvature piece within the
smoothing's allowance becomes one quintic (FITPACK adds no knot it does not
need), whose end tangent is off the arc's by 1.3e-6 rad for a 0.5 rad turn,
4e-5 for 1 rad, 2.4e-4 for 1.5 rad and 2e-3 for 3 rad (0.5 mm samples, 0.05 or
0.1 mm smoothing, measured).  Issue 35's 1e-4 rad at the default smoothing thus
holds for sections turning up to about 1.2 rad; ``resample.smoothing_mm: 0``
interpolates each piece (5e-9 rad on the same arcs).

A curve known piece by piece (``blend: pcc``: each designed section an exact
arc at every q) has its joints at the design's breaks, which need not be
samples of a uniform grid: :func:`grid_with_joints` makes a grid uniform on
each piece with every break a sample, and the curve is the pieces'
interpolants (5e-9 rad of end tangent on the demo's sections).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from softdesign.errors import GeometryError
from softdesign.types import FloatArray, Points

#: A link break is a joint when a polyline vertex and a resampling grid sample are both this close to it, as a
#: fraction of the sample spacing.  The vertex's arc length comes from the spline interpolating the whole path,
#: which rounds the corner: on seed 003's arcs with 0.5 mm samples it sits 6e-6 mm (1.2e-5 spacings) off the joint.
JOINT_TOL_SPACINGS = 1e-4


def joint_cuts(table: FloatArray, count: int, joints: FloatArray) -> list[tuple[int, int]]:
    """(polyline vertex, grid sample) of each joint that is both, within JOINT_TOL_SPACINGS, in order.

    Parameters
    ----------
    table : (n,) arc length at each polyline vertex along the spline interpolating them all, mm
    count : samples of the uniform resampling grid
    joints : (k,) normalized l of the candidate breaks (0 and 1 are ignored)
    """
    total = float(table[-1])
    spacing = total / (count - 1)
    cuts = []
    for l in np.unique(joints[(joints > 0.0) & (joints < 1.0)]):
        grid = int(round(l * (count - 1)))
        vertex = int(np.argmin(np.abs(table - l * total)))
        on_grid = abs(l * (count - 1) - grid) <= JOINT_TOL_SPACINGS
        if on_grid and abs(table[vertex] - l * total) <= JOINT_TOL_SPACINGS * spacing and 0 < grid < count - 1:
            cuts.append((vertex, grid))
    return cuts


def pieces_spline(l_grid: FloatArray, samples: Points, joints: tuple[int, ...], degree: int) -> BSpline:
    """One BSpline (values (3,) mm) of the interpolants on each piece between joints.

    Parameters
    ----------
    l_grid : (m,) uniform sample parameters
    samples : (m, 3) float, mm, at ``l_grid``
    joints : increasing indices of ``l_grid`` between which each piece has at least ``degree + 1`` samples
    degree : of every piece

    Each joint is a knot of multiplicity ``degree + 1``: the pieces share no coefficient, and meet at the
    joint's sample, which both interpolate.
    """
    bounds = [0, *joints, len(l_grid) - 1]
    if any(b - a < degree for a, b in zip(bounds[:-1], bounds[1:], strict=True)):
        raise GeometryError(
            f"curve samples: joints at samples {list(joints)} of {len(l_grid)} leave a piece of fewer than "
            f"{degree + 1} samples; expected at least {degree + 1} between joints (a smaller resample.spacing_mm)"
        )
    parts = [make_interp_spline(l_grid[a : b + 1], samples[a : b + 1], k=degree)
             for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    knots = np.concatenate([parts[0].t] + [part.t[degree + 1 :] for part in parts[1:]])
    return BSpline(knots, np.concatenate([part.c for part in parts]), degree)


def grid_with_joints(breaks: FloatArray, count: int, degree: int) -> tuple[FloatArray, tuple[int, ...]]:
    """Sample parameters (m,) with every break a sample, uniform on each piece, and the joints' indices.

    Parameters
    ----------
    breaks : (k + 1,) strictly increasing normalized l, 0 first and 1 last
    count : samples of the uniform grid the pieces are no coarser than (spacing 1 / (count - 1) in l)
    degree : each piece gets at least this many intervals (a piece of :func:`pieces_spline`)

    The breaks are kept bit for bit: a link whose ends are breaks starts and ends on samples.
    """
    spacing = 1.0 / (count - 1)
    pieces: list[FloatArray] = []
    ends: list[int] = []  # index of each piece's last sample
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        intervals = max(degree, math.ceil((b - a) / spacing - 1e-9))
        pieces.append(np.linspace(a, b, intervals + 1)[:-1])
        ends.append((ends[-1] if ends else 0) + intervals)
    return np.concatenate([*pieces, breaks[-1:]]), tuple(ends[:-1])


def checked_grid(l_grid: FloatArray, count: int) -> FloatArray:
    """``l_grid`` as (count,) float, checked: strictly increasing from 0 to 1.

    Raises
    ------
    GeometryError
        Another shape, or not strictly increasing from 0 to 1.
    """
    l_grid = np.asarray(l_grid, float)
    if l_grid.shape != (count,) or l_grid[0] != 0.0 or l_grid[-1] != 1.0 or np.any(np.diff(l_grid) <= 0.0):
        raise GeometryError(
            f"curve samples: expected their l as {count} values strictly increasing from 0 to 1, got shape "
            f"{l_grid.shape}" + (f" from {l_grid[0]:.6g} to {l_grid[-1]:.6g}" if l_grid.size else "")
        )
    return l_grid
