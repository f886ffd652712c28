"""Bounds of the case's shape sizes in mm (issue 36): what a soft actuator modelled on a human vessel can be.

Values outside them failed late with a message naming the wrong cause (a
radius of 1e-6 mm ended in "a bug in the mesher", a length of 1e-6 mm
advised resample.smoothing_mm, a radius or offset of metres advised
fit.end_cut); the schema now refuses them, naming the bound.

* ``initial.radius_mm``: from :data:`MIN_INITIAL_RADIUS_MM` (a tenth of the
  smallest vessel radius of :mod:`softdesign.geometry.plausibility`, 0.3 mm:
  finer than any mould prints) to :data:`MAX_INITIAL_RADIUS_MM` (five times
  the widest aorta's 20 mm);
* ``initial.length_mm``: from :data:`MIN_INITIAL_LENGTH_MM` (the shortest
  vessel path, 5 mm) to :data:`MAX_INITIAL_LENGTH_MM` (the longest, 2 m);
* ``export.offset_mm``: at most :data:`MAX_OFFSET_MM` outwards or inwards
  (the widest aorta's radius; an inward offset beyond the vessel's own
  radius is refused by the export once the radius is known).
"""

from __future__ import annotations

from collections.abc import Callable

MIN_INITIAL_RADIUS_MM = 0.03
MAX_INITIAL_RADIUS_MM = 100.0
MIN_INITIAL_LENGTH_MM = 5.0
MAX_INITIAL_LENGTH_MM = 2000.0
MAX_OFFSET_MM = 20.0


def size_bound(lowest: float, highest: float) -> Callable[[type, float | None], float | None]:
    """A pydantic field validator (classmethod body) refusing a size outside [lowest, highest] mm, naming both."""

    def check(cls: type, value: float | None) -> float | None:  # noqa: ARG001 - pydantic's validator signature
        if value is not None and not lowest <= value <= highest:
            raise ValueError(f"must be {lowest:g} to {highest:g} mm, got {value:g}")
        return value

    return check
