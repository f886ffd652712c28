"""Piecewise constant curvature (PCC) sections read by three cable encoders (seed 003).

Conventions
    Each section carries three cables (or chambers) at distance ``d`` (mm)
    from its backbone, at angles 90, 210 and 330 degrees from the section's
    base x axis (``ENCODER_ANGLES_RAD``).  A section is a circular arc of
    curvature ``kappa`` (1/mm, >= 0 from readings), arc length ``length``
    (mm) and bending-plane angle ``phi`` (rad, from x towards y); it bends
    *towards* ``phi``: the centre of curvature lies in direction ``phi``, so
    the cable at angle ``phi`` is the shortest (seed eq. 1-2):

        l_j = L - theta d cos(a_j - phi),    theta = kappa L.

    The base frame's z axis is the tangent at the base.  The tip frame is
    the base frame carried along the arc without twist, the seed's five-step
    chain ``Rz(phi) Ry(theta/2) Tz(2 sin(theta/2)/kappa) Ry(theta/2) Rz(-phi)``.
    A negative ``kappa`` is accepted by the transforms and means a bend
    towards ``phi + pi``.
Straight sections
    Every formula is written with ``sin(x)/x`` (``_sinc``), so ``kappa = 0``
    is exact (a translation of ``L`` along z) and the neighbourhood of 0 is
    smooth: no division by kappa anywhere.  ``phi`` is undefined when
    straight and is reported as 0.
Shapes
    Arrays broadcast: ``lengths`` is ``(..., 3)``, arc parameters ``(...)``,
    poses ``(..., 4, 4)``.  A chain of ``k`` sections is the last axis of the
    arc parameters, proximal first.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError, InputDataError
from softdesign.types import FloatArray, Pose

#: Angles of the three encoders (cables) on a section's end plate, rad (seed Fig. 6).
ENCODER_ANGLES_RAD = np.deg2rad([90.0, 210.0, 330.0])


class ArcParameters(NamedTuple):
    """The seed's geometric parameters of PCC sections; every field has shape (...)."""

    kappa: FloatArray  #: curvature, 1/mm, >= 0
    phi: FloatArray  #: bending-plane angle, rad, in (-pi, pi]; 0 when straight
    length: FloatArray  #: backbone arc length L, mm
    theta: FloatArray  #: bending angle kappa * L, rad


def _sinc(x: FloatArray) -> FloatArray:
    """``sin(x) / x`` with the value 1 at 0 (numpy's sinc is normalized by pi)."""
    return np.sinc(np.asarray(x, float) / np.pi)


def _as_float(value: npt.ArrayLike) -> FloatArray:
    return np.asarray(value, dtype=np.float64)


def check_lengths(lengths: npt.ArrayLike) -> FloatArray:
    """Encoder lengths as ``(..., 3)`` float64, each finite and > 0 mm.

    Raises
    ------
    InputDataError
        Wrong last axis, or a length that is not finite or not > 0.
    """
    lengths = _as_float(lengths)
    if lengths.ndim == 0 or lengths.shape[-1] != 3:
        raise InputDataError(
            f"pcc: encoder lengths must have shape (..., 3), one value per cable; got shape {lengths.shape}; "
            "give three lengths per section"
        )
    bad = ~(np.isfinite(lengths) & (lengths > 0))
    if np.any(bad):
        where = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputDataError(
            f"pcc: encoder lengths must be finite and > 0 mm; lengths{list(where)} is {float(lengths[where])}; "
            "check the readings"
        )
    return lengths


def check_spacing(d: npt.ArrayLike) -> FloatArray:
    """Cable-to-backbone distances ``d`` as float64, each finite and > 0 mm.

    Raises
    ------
    ConfigError
        A value that is not finite or not > 0.
    """
    d = _as_float(d)
    bad = ~(np.isfinite(d) & (d > 0))
    if np.any(bad):
        value = d[tuple(np.argwhere(bad)[0])] if d.ndim else d
        raise ConfigError(f"pcc: d (cable distance from the backbone) must be finite and > 0 mm, got {float(value)}")
    return d


def arcs_from_lengths(lengths: npt.ArrayLike, d: npt.ArrayLike) -> ArcParameters:
    """Arc parameters of sections from their three encoder lengths (seed eq. 3-5).

    Parameters
    ----------
    lengths : (..., 3) float, mm
        Cable lengths at 90, 210 and 330 degrees, each > 0.
    d : float or (...) float, mm
        Distance of the cables from the backbone, > 0; broadcast against
        ``lengths[..., 0]``.

    Returns
    -------
    ArcParameters
        ``kappa`` (1/mm, >= 0), ``phi`` (rad, by atan2 so every quadrant is
        right), ``length`` (mm, the mean of the three), ``theta`` (rad).
    """
    lengths = check_lengths(lengths)
    d = check_spacing(d)
    l1, l2, l3 = np.moveaxis(lengths, -1, 0)
    # theta d cos(phi) and theta d sin(phi), from differences of lengths:
    # better conditioned than eq. 5's sum of squares minus products.
    c = (l2 - l3) / np.sqrt(3.0)
    s = (l2 + l3 - 2.0 * l1) / 3.0
    bend = np.hypot(c, s)  # theta d
    phi = np.where(bend > 0, np.arctan2(s, c), 0.0)
    length = (l1 + l2 + l3) / 3.0
    theta = bend / d
    kappa = theta / length
    kappa, phi, length, theta = np.broadcast_arrays(kappa, phi, length, theta)
    return ArcParameters(kappa.copy(), phi.copy(), length.copy(), theta.copy())


def lengths_from_arcs(
    kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike, d: npt.ArrayLike
) -> FloatArray:
    """Encoder lengths of sections from arc parameters (seed eq. 2), the inverse of :func:`arcs_from_lengths`.

    ``l_j = L - kappa L d cos(a_j - phi)`` with ``a_j`` = 90, 210, 330 degrees.

    Parameters
    ----------
    kappa : (...) 1/mm;  phi : (...) rad;  length : (...) mm;  d : (...) mm, > 0

    Returns
    -------
    (..., 3) float, mm
    """
    d = check_spacing(d)
    kappa, phi, length = (_as_float(x) for x in (kappa, phi, length))
    theta_d = (kappa * length * d)[..., None]
    return length[..., None] - theta_d * np.cos(ENCODER_ANGLES_RAD - _as_float(phi)[..., None])


def tip_position_from_arc(kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike) -> FloatArray:
    """Tip of a section in its base frame (seed eq. 6), exact at kappa = 0.

    ``((1 - cos theta) cos phi, (1 - cos theta) sin phi, sin theta) / kappa``,
    written as ``L * (theta/2 sinc(theta/2)^2 cos phi, ... sin phi, sinc(theta))``.

    Parameters
    ----------
    kappa : (...) 1/mm;  phi : (...) rad;  length : (...) mm

    Returns
    -------
    (..., 3) float, mm
    """
    kappa, phi, length = np.broadcast_arrays(*(_as_float(x) for x in (kappa, phi, length)))
    theta = kappa * length
    half = 0.5 * theta
    radial = length * half * _sinc(half) ** 2  # (1 - cos theta) / kappa
    axial = length * _sinc(theta)  # sin theta / kappa
    return np.stack([radial * np.cos(phi), radial * np.sin(phi), axial], axis=-1)


def transform_from_arc(kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike) -> Pose:
    """Tip-to-base pose of a section, closed form of ``Rz(phi) Ry(theta/2) Tz(rho) Ry(theta/2) Rz(-phi)``.

    ``rho = 2 sin(theta/2) / kappa = L sinc(theta/2)`` is the chord (seed eq. 7);
    the rotation is ``Rz(phi) Ry(theta) Rz(-phi)`` (seed eq. 8).

    Parameters
    ----------
    kappa : (...) 1/mm;  phi : (...) rad;  length : (...) mm

    Returns
    -------
    (..., 4, 4) float
        Maps coordinates in the section's tip frame into its base frame.
    """
    kappa, phi, length = np.broadcast_arrays(*(_as_float(x) for x in (kappa, phi, length)))
    theta = kappa * length
    cp, sp = np.cos(phi), np.sin(phi)
    ct, st = np.cos(theta), np.sin(theta)
    vers = 2.0 * np.sin(0.5 * theta) ** 2  # 1 - cos theta, without cancellation near 0
    pose = np.zeros(kappa.shape + (4, 4))
    pose[..., 0, :3] = np.stack([1.0 - cp * cp * vers, -sp * cp * vers, cp * st], axis=-1)
    pose[..., 1, :3] = np.stack([-sp * cp * vers, 1.0 - sp * sp * vers, sp * st], axis=-1)
    pose[..., 2, :3] = np.stack([-cp * st, -sp * st, ct], axis=-1)
    pose[..., :3, 3] = tip_position_from_arc(kappa, phi, length)
    pose[..., 3, 3] = 1.0
    return pose


def dh_table_from_arc(kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike) -> FloatArray:
    """The seed's improved D-H table of a section (Table 1), standard D-H convention.

    Rows are the five steps; columns ``(theta, d, a, alpha)`` in rad, mm, mm,
    rad, for links ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``.  The ``alpha = -pi/2,
    +pi/2`` pairs turn the middle rotations about z into rotations about y.

    Parameters
    ----------
    kappa : (...) 1/mm;  phi : (...) rad;  length : (...) mm

    Returns
    -------
    (..., 5, 4) float
    """
    kappa, phi, length = np.broadcast_arrays(*(_as_float(x) for x in (kappa, phi, length)))
    half = 0.5 * kappa * length
    chord = length * _sinc(half)  # 2 sin(theta/2) / kappa
    zero = np.zeros_like(kappa)
    quarter = np.full_like(kappa, 0.5 * np.pi)
    rows = [
        (phi, zero, zero, -quarter),
        (half, zero, zero, quarter),
        (zero, chord, zero, -quarter),
        (half, zero, zero, quarter),
        (-phi, zero, zero, zero),
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


#: The columns of :func:`dh_table_from_arc`, as seed 003's Table 1 orders them.
DH_COLUMNS = ("theta", "d", "a", "alpha")
#: How the rows compose, for JSON documents that carry them.
DH_CONVENTION = ("improved D-H rows of Zou et al. (Table 1), standard D-H links Rz(theta) Tz(d) Tx(a) Rx(alpha), "
                 "multiplied in row order: the product is the section's transform (rad, mm)")


def dh_rows(kappa: float, phi: float, length: float) -> list[dict[str, float]]:
    """Seed 003's five D-H rows of one section as ``{"theta", "d", "a", "alpha"}`` (rad, mm, mm, rad).

    ``+ 0.0`` writes -0.0 (e.g. ``-phi`` at phi = 0) as 0.0.
    """
    table = dh_table_from_arc(kappa, phi, length) + 0.0
    return [{name: float(value) for name, value in zip(DH_COLUMNS, row, strict=True)} for row in table]


def transform_from_dh(theta: npt.ArrayLike, d: npt.ArrayLike, a: npt.ArrayLike, alpha: npt.ArrayLike) -> Pose:
    """One standard D-H link, ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``.

    Parameters
    ----------
    theta : (...) rad;  d : (...) mm;  a : (...) mm;  alpha : (...) rad

    Returns
    -------
    (..., 4, 4) float
    """
    theta, d, a, alpha = np.broadcast_arrays(*(_as_float(x) for x in (theta, d, a, alpha)))
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    pose = np.zeros(theta.shape + (4, 4))
    pose[..., 0, :] = np.stack([ct, -st * ca, st * sa, a * ct], axis=-1)
    pose[..., 1, :] = np.stack([st, ct * ca, -ct * sa, a * st], axis=-1)
    pose[..., 2, 1:] = np.stack([sa, ca, d], axis=-1)
    pose[..., 3, 3] = 1.0
    return pose


def transform_from_dh_table(table: npt.ArrayLike) -> Pose:
    """Product of the links of a standard D-H table, first row first.

    Parameters
    ----------
    table : (..., r, 4) float
        Rows ``(theta, d, a, alpha)``, rad, mm, mm, rad.

    Returns
    -------
    (..., 4, 4) float
        Last link's frame to the first link's base.
    """
    table = _as_float(table)
    if table.ndim < 2 or table.shape[-1] != 4 or table.shape[-2] == 0:
        raise ConfigError(
            f"pcc: a D-H table has at least one row (theta, d, a, alpha), shape (..., r, 4); got {table.shape}"
        )
    links = transform_from_dh(*np.moveaxis(table, -1, 0))
    return chain_transforms(links)[..., -1, :, :]


def chain_transforms(section2prev: npt.ArrayLike) -> Pose:
    """Cumulative poses of a chain: ``section_i2base = section2prev[0] @ ... @ section2prev[i]``.

    The seed's recursion (9) for ``T_i`` is garbled in print (it multiplies
    ``T^i_{i-1}`` by ``T^i_{i+1}``); the chain is the plain matrix product of
    the section transforms, proximal first, which is what its eq. 10 uses.

    Parameters
    ----------
    section2prev : (..., k, 4, 4) float
        Each section's tip frame in the tip frame of the previous one.

    Returns
    -------
    (..., k, 4, 4) float
        Each section's tip frame in the base frame of the first section.
    """
    section2prev = _as_float(section2prev)
    if section2prev.ndim < 3 or section2prev.shape[-2:] != (4, 4):
        raise ConfigError(f"pcc: a chain is (..., k, 4, 4) section poses; got shape {section2prev.shape}")
    out = np.empty_like(section2prev)
    if section2prev.shape[-3] == 0:
        return out
    out[..., 0, :, :] = section2prev[..., 0, :, :]
    for i in range(1, section2prev.shape[-3]):
        out[..., i, :, :] = out[..., i - 1, :, :] @ section2prev[..., i, :, :]
    return out


def sample_backbone_poses(
    kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike, points_per_section: int = 21
) -> Pose:
    """Poses along the backbone of a chain of arcs, equally spaced in arc length per section.

    Parameters
    ----------
    kappa, phi, length : (..., k) 1/mm, rad, mm
        The arcs, proximal first.
    points_per_section : int, >= 2
        Samples per arc, both ends included; a junction is kept once.

    Returns
    -------
    (..., n, 4, 4) float, n = k (m - 1) + 1
        Sample frames in the base frame: z is the tangent, translation is
        the backbone point (mm); the first is the identity.
    """
    if int(points_per_section) != points_per_section or points_per_section < 2:
        raise ConfigError(f"pcc: points per section must be an integer >= 2, got {points_per_section}")
    kappa, phi, length = np.broadcast_arrays(*(_as_float(x) for x in (kappa, phi, length)))
    if kappa.ndim == 0 or kappa.shape[-1] == 0:
        raise ConfigError(f"pcc: a backbone needs at least one section, got arc parameters of shape {kappa.shape}")
    fraction = np.linspace(0.0, 1.0, int(points_per_section))
    # (..., k, m, 4, 4): samples of each arc in that arc's base frame.
    local = transform_from_arc(kappa[..., None], phi[..., None], length[..., None] * fraction)
    tips = chain_transforms(transform_from_arc(kappa, phi, length))
    bases = np.concatenate([np.broadcast_to(np.eye(4), tips[..., :1, :, :].shape), tips[..., :-1, :, :]], axis=-3)
    placed = bases[..., None, :, :] @ local
    head = placed[..., 0, :, :, :]
    k, m = kappa.shape[-1], len(fraction)
    rest = placed[..., 1:, 1:, :, :].reshape(kappa.shape[:-1] + ((k - 1) * (m - 1), 4, 4))
    return np.concatenate([head, rest], axis=-3)


def sample_backbone(
    kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike, points_per_section: int = 21
) -> FloatArray:
    """Points along the backbone of a chain of arcs, (..., n, 3) mm; see :func:`sample_backbone_poses`."""
    return sample_backbone_poses(kappa, phi, length, points_per_section)[..., :3, 3]


def backbone_arc_lengths(
    length: npt.ArrayLike, points_per_section: int = 21
) -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """Arc length from the base and section index of every sample of :func:`sample_backbone_poses`.

    Parameters
    ----------
    length : (..., k) mm
    points_per_section : int, >= 2

    Returns
    -------
    arc_length : (..., n) float, mm
    section : (n,) int, 0-based; a junction belongs to the proximal section
    """
    length = _as_float(length)
    m = int(points_per_section)
    fraction = np.linspace(0.0, 1.0, m)
    starts = np.cumsum(length, axis=-1) - length
    along = starts[..., None] + length[..., None] * fraction  # (..., k, m)
    k = length.shape[-1]
    rest = along[..., 1:, 1:].reshape(length.shape[:-1] + ((k - 1) * (m - 1),))
    arc_length = np.concatenate([along[..., 0, :], rest], axis=-1)
    section = np.concatenate([np.zeros(m, np.int64), np.repeat(np.arange(1, k, dtype=np.int64), m - 1)])
    return arc_length, section
