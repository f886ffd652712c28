"""Lengths as messages print them: three significant figures in the files' unit, with mm beside it otherwise.

The case file's ``units`` is the unit the user's files and ``final.inlet`` are
written in, so a length a message reports is given in it (a user compares it
with their own viewer); the project works in mm, so mm stands beside any other
unit: ``0.0703 m (70.3 mm)``.  Three significant figures are the precision a
centerline or a radius has (VMTK's own placement noise is a tenth of a surface
edge); two decimals of a metre (``0.07 m``) said nothing.
"""

from __future__ import annotations

import math

from softdesign.types import UNIT_SCALE_TO_MM

#: Significant figures of a printed length.
LENGTH_FIGURES = 3


def figures(value: float, count: int = LENGTH_FIGURES) -> str:
    """``value`` to ``count`` significant figures, positional, trailing zeros kept: ``1230``, ``0.0400``, ``5.00``.

    No exponent (``1.23e+03`` reads badly beside a viewer's numbers); zeros that are figures stay, so
    ``0.0400 m`` says it is known to a tenth of a millimetre.
    """
    value = float(f"{float(value):.{count - 1}e}")  # rounded first, so that 9.996 gives 10.0, not 10.00
    if value == 0.0 or not math.isfinite(value):
        return f"{value:.{count - 1}f}" if value == 0.0 else str(value)
    decimals = count - 1 - math.floor(math.log10(abs(value)))
    return f"{value:.{decimals}f}" if decimals >= 0 else f"{value:.0f}"


def length_text(value_mm: float, units: str) -> str:
    """A length given in mm, printed in ``units`` (mm, cm or m): ``70.3 mm``, ``7.03 cm (70.3 mm)``.

    Raises
    ------
    KeyError
        ``units`` is not one of mm, cm, m.
    """
    if units == "mm":
        return f"{figures(value_mm)} mm"
    return f"{figures(value_mm / UNIT_SCALE_TO_MM[units])} {units} ({figures(value_mm)} mm)"
