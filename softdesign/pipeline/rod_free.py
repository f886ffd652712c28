"""``backbone: free`` with ``supply: single``: the rest (cast) lengths the rod model gives, and the body's morph.

Without an axis thread the pressure also stretches each section: at P = q P* the rod model's section i is
``L0_i (1 + q eps_i)`` long (eps_i its mean axial strain at P*, linear in P) and turns through ``q theta_i``.
For it to reach the designed arc (length L_i, turn theta_i = kappa_i L_i) at P*, it is cast ``L0_i = L_i /
(1 + eps_i)`` long and sized on that rest length; eps_i depends on the chambers sized on L0, so the two are
solved in turn until L0 settles (:func:`settled`, ``REST_ATOL_MM``).  The sizing then asks each section for
its designed turn over its rest length: bending ``w_i L_i / L0_i``.

The morph at q is the rod model's: section i of length ``L0_i + q (L_i - L0_i)`` (= ``L0_i (1 + q eps_i)``)
turning through ``q theta_i`` in its plane, composed from the base frame.  The meshes and the mould take the body
on that chain (:func:`body_curve_at`): at q = 0 it is shorter than the vessel's path.  The body's l keeps its
joints at the design's breaks and is proportional to arc length within each section (each section stretches
uniformly: the model's strain varies along a tapered section, so this is its mean); the radius field is the
fitted one at (q, l).  The kinematics, fit and feasibility stages keep the designed lengths (``blend: pcc``),
so their figures are those of the designed morph.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

if TYPE_CHECKING:
    from softdesign.geometry.frames import FramedSpline
    from softdesign.pipeline.stages.kinematics import KinematicsResult

#: The rest lengths are settled when no section's moves by more than this between two sizings, mm.
REST_ATOL_MM = 1e-9
#: At most this many sizings (on the demo the change falls about 10-fold per sizing, from 11 mm).
REST_SIZINGS = 12


def morph_chain(w: npt.ArrayLike, lengths: npt.ArrayLike, rest: npt.ArrayLike, q: float
                ) -> tuple[FloatArray, FloatArray]:
    """The chain at q: each section's bending (n, 2) 1/mm and length (n,) mm: ``L0 + q (L - L0)``, turning
    ``q w L``."""
    w, lengths, rest = (np.asarray(x, float) for x in (w, lengths, rest))
    now = rest + q * (lengths - rest)
    return q * w * (lengths / now)[:, None], now


def s_from_l(breaks: npt.ArrayLike, lengths: npt.ArrayLike, l: npt.ArrayLike) -> FloatArray:
    """Arc length (mm) along a chain of sections ``lengths`` (n,) at normalized ``l``: linear within each section
    between its breaks (n + 1,)."""
    breaks, lengths = np.asarray(breaks, float), np.asarray(lengths, float)
    return np.asarray(np.interp(np.asarray(l, float), breaks, np.concatenate([[0.0], np.cumsum(lengths)])), float)


def l_from_s(breaks: npt.ArrayLike, lengths: npt.ArrayLike, s: npt.ArrayLike) -> FloatArray:
    """Normalized l at arc lengths ``s`` (mm) along a chain of sections ``lengths``: :func:`s_from_l`'s inverse."""
    breaks, lengths = np.asarray(breaks, float), np.asarray(lengths, float)
    return np.asarray(np.interp(np.asarray(s, float), np.concatenate([[0.0], np.cumsum(lengths)]), breaks), float)


def settled(rest: FloatArray, new: FloatArray) -> bool:
    """Whether two successive rest lengths agree within ``REST_ATOL_MM``."""
    return bool(np.max(np.abs(np.asarray(new) - np.asarray(rest))) <= REST_ATOL_MM)


def morph_document(base2world: npt.ArrayLike, w: npt.ArrayLike, lengths: npt.ArrayLike, rest: npt.ArrayLike,
                   breaks: npt.ArrayLike) -> dict[str, Any]:
    """The actuation summary's ``free_morph``: what :func:`body_curve_at` builds the body's chain from."""
    return {"base2world": np.asarray(base2world, float).tolist(), "w": np.asarray(w, float).tolist(),
            "lengths": np.asarray(lengths, float).tolist(), "rest_lengths": np.asarray(rest, float).tolist(),
            "breaks": np.asarray(breaks, float).tolist()}


def body_curve_at(kinematics: KinematicsResult, summary: dict[str, Any] | None, q: float) -> FramedSpline:
    """The centreline the body is meshed on at q: the rest-length morph's (``free_morph`` in the actuation
    ``summary``), else the kinematics' own."""
    shape = kinematics.chain.shape
    morph = None if summary is None else summary.get("free_morph")
    if morph is None:
        return shape.curve_at(q)
    from softdesign.geometry.curves import smooth_curve_from_samples
    from softdesign.geometry.frames import framed_curve
    from softdesign.kinematics.pcc_chain import chain_points_at

    w, lengths = morph_chain(morph["w"], morph["lengths"], morph["rest_lengths"], q)
    smooth = shape.smooth_curve_at(q)
    points = chain_points_at(morph["base2world"], w, lengths, s_from_l(morph["breaks"], lengths, smooth.l_grid))
    curve = smooth_curve_from_samples(points, smooth.joints, smooth.l_grid)
    return framed_curve(curve, shape.frames, shape.base_normal, label=f"q = {q:g} (rest lengths)")
