"""The figures a regression check produces, its tolerances, and the helpers every comparison shares.

:class:`Figure` is one compared figure, :class:`CheckOptions` the tolerances
and :class:`CheckReport` a whole check; :func:`scalar_figure` and
:func:`missing_figure` make the figures common to meshes, kinematics and fit.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, TypeGuard

from softdesign.errors import ConfigError, InputDataError
from softdesign.meshing.compare import DEFAULT_SAMPLES

Value = float | bool | str | None

#: A residual (how far a fitted or designed thing is from its target: the fit's errors, a design's deviation and
#: tip error, a link's misfit of one arc) agrees within the smaller of the absolute tolerance and ``rtol`` of the
#: reference plus this floor, mm: far above the round-off of a rebuild (1e-13 mm), far below any change that
#: matters.  Residuals are often far below ``distance_mm`` (1e-4 mm on a synthetic vessel, 0.1 mm for a design's
#: tip), where an absolute tolerance alone would let a change of a percent of them pass unseen.
RESIDUAL_FLOOR_MM = 1e-6
#: The same floor for an angle residual, degrees (1.7e-8 rad).
RESIDUAL_FLOOR_DEG = 1e-6


@dataclass(frozen=True)
class CheckOptions:
    """Tolerances of a check, and the sampling of the surface distance.

    Attributes
    ----------
    distance_mm : surface distance, transform translation, lengths, fit metrics, mm
    rtol : relative change of volume and area
    rotation_rad : rotation between link transforms and POE theta2, rad
    samples : fewest surface points sampled per mesh
    """

    distance_mm: float = 0.01
    rtol: float = 1e-3
    rotation_rad: float = 1e-4
    samples: int = DEFAULT_SAMPLES

    def __post_init__(self) -> None:
        for name, option in (("distance_mm", "--tolerance-mm"), ("rtol", "--rtol"), ("rotation_rad", "--rotation-tol")):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"{option}: expected a finite tolerance >= 0, got {value}")
        if self.samples < 1:
            raise ConfigError(f"samples: expected >= 1, got {self.samples}")


@dataclass(frozen=True)
class Figure:
    """One compared figure: how much it moved, its tolerance and the verdict.

    ``change`` is build minus reference for scalars, the distance or angle for
    poses and meshes, None where a thing is missing; ``passed`` is
    ``|change| <= tolerance`` (or equality where ``tolerance`` is None).
    """

    item: str
    figure: str
    change: Value
    tolerance: float | None
    passed: bool
    build: Value = None
    reference: Value = None
    note: str = ""

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: field name -> value, a non-finite number as None."""
        return {key: _json_value(value) for key, value in asdict(self).items()}


@dataclass(frozen=True)
class CheckReport:
    """Every figure of one check, in order: meshes, kinematics, fit."""

    build_dir: Path
    reference_dir: Path
    options: CheckOptions
    figures: tuple[Figure, ...]
    notes: tuple[str, ...] = field(default=())
    #: The build and the reference look like different cases (names or input files differ).
    warnings: tuple[str, ...] = field(default=())

    @property
    def passed(self) -> bool:
        """True when every figure is within its tolerance."""
        return all(f.passed for f in self.figures)

    @property
    def failures(self) -> tuple[Figure, ...]:
        """The figures outside tolerance."""
        return tuple(f for f in self.figures if not f.passed)

    def as_dict(self, failures_only: bool = False) -> dict[str, Any]:
        """The JSON object ``softdesign check --json`` prints; ``figures`` holds only the failures if asked."""
        return {
            "passed": self.passed,
            "build": self.build_dir.as_posix(),
            "reference": self.reference_dir.as_posix(),
            "tolerances": {key: getattr(self.options, key) for key in ("distance_mm", "rtol", "rotation_rad")},
            "compared": len(self.figures),
            "failures": len(self.failures),
            "figures": [f.as_dict() for f in (self.failures if failures_only else self.figures)],
            "notes": list(self.notes),
            "warnings": list(self.warnings),
        }


def scalar_figure(item: str, figure: str, value: Any, reference: Any, tolerance: float) -> Figure:
    """``value - reference`` within ``tolerance``; a value on one side only fails."""
    if value is None or reference is None:
        if value is None and reference is None:
            return Figure(item, figure, None, tolerance, True, note="absent on both sides")
        return missing_figure(item, figure, in_build=value is not None)
    if not (is_number(value) and is_number(reference)):
        return Figure(item, figure, None, tolerance, False, str(value), str(reference), "expected two numbers")
    change = float(value) - float(reference)
    return Figure(item, figure, change, tolerance, abs(change) <= tolerance, float(value), float(reference))


def missing_figure(item: str, figure: str, in_build: bool) -> Figure:
    """A thing on one side only: always a failure."""
    sides = ("present", "missing") if in_build else ("missing", "present")
    return Figure(item, figure, None, None, False, *sides)


def read_json(path: Path) -> dict:
    """The JSON object in ``path``; InputDataError when it is unreadable or not an object."""
    try:
        payload = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputDataError(f"{path}: cannot read JSON ({err}); rebuild it") from err
    except RecursionError:
        raise InputDataError(f"{path}: its JSON is nested too deep to be a softdesign file; rebuild it") from None
    if not isinstance(payload, dict):
        raise InputDataError(f"{path}: expected a JSON object, got {type(payload).__name__}")
    return payload


def residual_tolerance(reference: Any, absolute: float, rtol: float | None, floor: float) -> float:
    """A residual's tolerance: the smaller of ``absolute`` and ``rtol * |reference| + floor`` (``absolute`` alone
    without ``rtol`` or a numeric reference); see :data:`RESIDUAL_FLOOR_MM`."""
    if rtol is None or not is_number(reference):
        return absolute
    return min(absolute, rtol * abs(float(reference)) + floor)


def is_number(value: Any) -> TypeGuard[int | float]:
    """An int or float, not a bool."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _json_value(value: Value) -> Value:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
