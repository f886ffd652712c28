"""The wall fit's options from the case file, for the fit stage and for ``blend: auto``'s look at the body."""

from __future__ import annotations

from typing import TYPE_CHECKING

from softdesign.fitting.bspline_surface import FitSettings
from softdesign.fitting.local_cap import LocalCap
from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.fitting.metrics import HoldoutSettings
from softdesign.fitting.selection import SelectionSettings
from softdesign.fitting.wall_fit import WallFitOptions

if TYPE_CHECKING:
    from softdesign.config import Case

#: The knot spacing ``fit.knot_spacing_mm: auto`` starts from where no hold-out chooses one, mm (the default's).
AUTO_START_SPACING_MM = 1.5


def wall_fit_options(case: Case, breaks: tuple[float, ...], mapper: Mapper = serial_map) -> WallFitOptions:
    """Every setting of the wall fit the case gives, with the links' ``breaks`` (normalized l)."""
    fit = case.fit
    settings = FitSettings(
        # the only text knot_spacing_mm takes is 'auto' (then the fit chooses the spacing by hold-out)
        1.0 if isinstance(fit.knot_spacing_mm, str) else fit.knot_spacing_mm,
        fit.angular_intervals,
        fit.smoothing,
        tuple(breaks),
    )
    return WallFitOptions(
        fit=settings,
        auto_spacing=fit.knot_spacing_mm == "auto",
        selection=SelectionSettings(outlier_factor=fit.outlier_factor),
        holdout=HoldoutSettings(folds=fit.holdout_folds),
        initial_radius_mm=case.initial.radius_mm,
        end_margin_mm=fit.end_margin_mm,
        max_radius_mm=fit.max_radius_mm,
        local_caps=tuple(LocalCap(c.from_mm, c.to_mm, c.radius_mm, c.taper_mm) for c in fit.local_max_radius),
        mapper=mapper,
    )
