"""Seed 003's three chambers per section, one pressure each: the rod model's inverse (issue 41).

The rod model (:mod:`softdesign.kinematics.rod`) is linear in the 3n pressures; section i bends under its own
chambers and the feeds of the distal ones, so the sections are solved distal first: the section's rotation
``int w ds`` (and with ``backbone: free`` its length) equals the target's.  With an inextensible backbone two
equations leave one free combination (equal moments cancelling): the lowest pressures, one chamber at zero, are
chosen.  Pure numpy; kPa and mm.
"""

from __future__ import annotations

import numpy as np

from softdesign.kinematics.rod import RodBody, strains
from softdesign.types import FloatArray


def per_chamber_pressures(body: RodBody, rotation: FloatArray, stretch: FloatArray | None) -> FloatArray:
    """Every channel's pressure (c,) kPa, distal sections first, for each section's rotation and length.

    Parameters
    ----------
    body : three channels per section (section i's are 3 i, 3 i + 1, 3 i + 2)
    rotation : (n, 2) rad, each section's ``int w ds`` (its theta (cos phi, sin phi))
    stretch : (n,) mm, each section's ``int eps0 ds`` (``backbone: free``), None when inextensible

    Returns the pressures; a negative one is returned as is (the caller refuses it, naming the section).
    """
    n = int(body.section.max()) + 1
    unit = np.eye(body.channels)
    response = [strains(body, unit[c]) for c in range(body.channels)]
    eps = np.stack([r[0] for r in response], axis=1)  # (k, c)
    w = np.stack([r[1] for r in response], axis=2)  # (k, 2, c)
    pressures = np.zeros(body.channels)
    for i in reversed(range(n)):
        at = body.section == i
        own = np.arange(3 * i, 3 * i + 3)
        rows = [np.einsum("k,kic->ic", body.ds[at], w[at])]
        goal = [rotation[i]]
        if stretch is not None:
            rows.append(np.einsum("k,kc->c", body.ds[at], eps[at])[None])
            goal.append(np.asarray([stretch[i]]))
        matrix, rhs = np.concatenate(rows), np.concatenate(goal)
        rhs = rhs - matrix @ pressures
        solution, *_ = np.linalg.lstsq(matrix[:, own], rhs, rcond=None)
        if stretch is None:
            null = np.linalg.svd(matrix[:, own])[2][-1]
            null = null if null.sum() > 0 else -null
            solution = solution - np.min(solution / null) * null  # the lowest: one chamber at zero
        pressures[own] = solution
    return pressures
