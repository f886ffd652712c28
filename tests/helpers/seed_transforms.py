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


def seed_chain(kappa: float, phi: float, length: float) -> np.ndarray:
    """Seed section 3.2's five steps Rz(phi) Ry(theta/2) Tz(chord) Ry(theta/2) Rz(-phi), chord from eq. 7
    (a straight section, kappa = 0: the chord is its length)."""
    theta = kappa * length
    chord = length if kappa == 0.0 else 2.0 / kappa * np.sin(theta / 2)
    return rot_z(phi) @ rot_y(theta / 2) @ trans_z(chord) @ rot_y(theta / 2) @ rot_z(-phi)
