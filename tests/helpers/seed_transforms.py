"""Seed 003's improved D-H section transform built independently from elementary matrices (test helper)."""

from __future__ import annotations

import numpy as np


def rot_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def rot_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def trans_z(distance: float) -> np.ndarray:
    out = np.eye(4)
    out[2, 3] = distance
    return out


def dh_link(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """A standard D-H link Rz(theta) Tz(d) Tx(a) Rx(alpha), from elementary matrices."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    rot_x = np.array([[1, 0, 0, 0], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1.0]])
    trans_x = np.eye(4)
    trans_x[0, 3] = a
    return rot_z(theta) @ trans_z(d) @ trans_x @ rot_x


def dh_product(rows: list[dict[str, float]]) -> np.ndarray:
    """The product of D-H rows ``{"theta", "d", "a", "alpha"}`` as the JSON outputs write them, first row first."""
    product = np.eye(4)
    for row in rows:
        product = product @ dh_link(row["theta"], row["d"], row["a"], row["alpha"])
    return product


def seed_chain(kappa: float, phi: float, length: float) -> np.ndarray:
    """Seed section 3.2's five steps Rz(phi) Ry(theta/2) Tz(chord) Ry(theta/2) Rz(-phi), chord from eq. 7
    (a straight section, kappa = 0: the chord is its length)."""
    theta = kappa * length
    chord = length if kappa == 0.0 else 2.0 / kappa * np.sin(theta / 2)
    return rot_z(phi) @ rot_y(theta / 2) @ trans_z(chord) @ rot_y(theta / 2) @ rot_z(-phi)
