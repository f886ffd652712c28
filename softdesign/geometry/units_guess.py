"""Which unit were a vessel's files written in?  A guess from the vessel's size, with its evidence.

VMTK writes whatever unit the image was segmented in: millimetres from most
scanners' DICOM, metres from some simulation pipelines, centimetres from a
few.  The files do not say.  A human vessel path is 5 mm to 2 m long with a
median inscribed radius of 0.3 to 20 mm (:mod:`softdesign.geometry.plausibility`);
the three units are a factor of 10 or 1000 apart, so read in the wrong one a
vessel is usually far outside those bands.  Usually, not always: a 60 mm
path of radius 2 mm read in cm is 600 mm long with radius 20 mm, still
human.  Then the guess is refused rather than made: :class:`UnitGuess` has
no unit, and its evidence lists every reading that was plausible.

No files, no printing: numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.geometry.plausibility import PLAUSIBLE_LENGTH_MM, PLAUSIBLE_RADIUS_MM, plausible_vessel
from softdesign.types import UNIT_SCALE_TO_MM


@dataclass(frozen=True)
class UnitGuess:
    """The unit the files were written in, or None when the sizes allow more than one (or none).

    Attributes
    ----------
    units : "mm", "cm" or "m", or None when the evidence is ambiguous or fits no unit
    plausible : every unit in which all the paths are a human vessel's size
    evidence : one sentence per unit tried: the longest path and the median radius read in it
    """

    units: str | None
    plausible: tuple[str, ...]
    evidence: tuple[str, ...]


def guess_units(lengths: npt.ArrayLike, median_radii: npt.ArrayLike | None) -> UnitGuess:
    """The unit in which every path (its length and median radius, in the file's own numbers) is a human vessel's.

    Parameters
    ----------
    lengths : (p,) float -- each path's length, in the file's unit
    median_radii : (p,) float or None -- each path's median inscribed radius (or opening radius), file's unit

    Returns
    -------
    UnitGuess
        ``units`` set only when exactly one unit makes every path plausible.
    """
    lengths = np.asarray(lengths, float).ravel()
    radii = None if median_radii is None else np.asarray(median_radii, float).ravel()
    if len(lengths) == 0 or (radii is not None and radii.shape != lengths.shape):
        raise ValueError(f"need one length per path and one radius each, got {lengths.shape} and "
                         f"{None if radii is None else radii.shape}")
    plausible = []
    evidence = []
    for units, scale in UNIT_SCALE_TO_MM.items():
        ok = all(
            plausible_vessel(float(length) * scale, None if radii is None else float(radius) * scale)
            for length, radius in zip(lengths, radii if radii is not None else lengths, strict=True)
        )
        if ok:
            plausible.append(units)
        evidence.append(_reading(units, scale, lengths, radii, ok))
    chosen = plausible[0] if len(plausible) == 1 else None
    return UnitGuess(chosen, tuple(plausible), tuple(evidence))


def _reading(units: str, scale: float, lengths: np.ndarray, radii: np.ndarray | None, ok: bool) -> str:
    """``in cm: paths 66.2 to 77.8 mm long, median radius 4.1 to 7.2 mm: a human vessel``."""
    span = f"paths {lengths.min() * scale:.4g} to {lengths.max() * scale:.4g} mm long"
    if radii is not None:
        span += f", median radius {radii.min() * scale:.3g} to {radii.max() * scale:.3g} mm"
    verdict = "a human vessel" if ok else (
        f"not a human vessel (expected {PLAUSIBLE_LENGTH_MM[0]:g} to {PLAUSIBLE_LENGTH_MM[1]:g} mm long"
        + ("" if radii is None else f", median radius {PLAUSIBLE_RADIUS_MM[0]:g} to {PLAUSIBLE_RADIUS_MM[1]:g} mm")
        + ")"
    )
    return f"in {units}: {span}: {verdict}"
