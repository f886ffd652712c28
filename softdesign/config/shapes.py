"""The case's shapes: ``final`` (the patient's, q = 1), ``initial`` (the insertion shape, q = 0) and the
``intermediate`` keyframes between them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, field_validator, model_validator

from softdesign.config.types import CaseBlock, FiniteFloat, Flag, Integer
from softdesign.limits.shape import (
    MAX_INITIAL_LENGTH_MM,
    MAX_INITIAL_RADIUS_MM,
    MIN_INITIAL_LENGTH_MM,
    MIN_INITIAL_RADIUS_MM,
    size_bound,
)


class FinalShape(CaseBlock):
    """The patient's shape, q = 1.

    ``centerline: auto`` extracts it from ``surface`` at ingest (softdesign.centerline, as
    ``softdesign centerline`` does); the file it makes is kept in the build folder.
    """

    centerline: Literal["auto"] | Path
    """The centerline file (.vtp .vtk .vtu .csv .npy), or auto to extract it from the surface at ingest."""
    surface: Path | None = None
    """The vessel surface (.stl .vtp .ply .obj .vtk), capped or open."""
    path: Integer = Field(0, ge=0)
    """Which path of the centerline network the actuator follows (a polyline index, or CenterlineIds when
    branch-split).
    """
    inlet: tuple[FiniteFloat, FiniteFloat, FiniteFloat] | None = None
    """A point near the inlet: the path's end nearest it is l = 0, where the actuator is mounted."""
    reverse: Flag = False
    """Flip the path's orientation (when the inlet rule picks the wrong end)."""
    surface_units: Literal["mm", "cm", "m"] | None = None
    """The surface file's unit when it differs from the case's units."""

    @model_validator(mode="after")
    def _auto_needs_surface(self) -> FinalShape:
        if self.centerline == "auto" and self.surface is None:
            raise ValueError("centerline: auto extracts the centerline from the surface: give surface too")
        return self


class IntermediateShape(CaseBlock):
    """A keyframe centerline reached at ``q`` (piecewise-linear in q between keyframes)."""

    q: FiniteFloat = Field(gt=0.0, lt=1.0)
    """The q at which this keyframe is reached, strictly between 0 and 1."""
    centerline: Path
    """The keyframe's centerline file."""
    path: Integer = Field(0, ge=0)
    """Which path of the keyframe's centerline file."""
    reverse: Flag = False
    """Flip the keyframe path's orientation."""


class InitialShape(CaseBlock):
    """The insertion shape, q = 0, and the body radius there."""

    kind: Literal["straight", "arc", "file"] = "straight"
    """The q = 0 shape: straight, an arc, or a file."""
    length_mm: FiniteFloat | None = Field(None, gt=0.0)
    """Length of the q = 0 centerline, mm (default: the q = 1 centerline's)."""
    radius_mm: FiniteFloat | None = Field(None, gt=0.0)
    """A constant body radius at q = 0, mm (default: the fitted wall's axially symmetric mean)."""
    surface: Path | None = None
    """A surface for the q = 0 body instead of a constant radius."""
    bend_radius_mm: FiniteFloat | None = Field(None, gt=0.0)
    """The arc's radius of curvature, mm (kind: arc)."""
    bend_plane_deg: FiniteFloat = 0.0
    """The arc's bending plane about the base tangent, degrees from the base frame's N (kind: arc)."""
    centerline: Path | None = None
    """The q = 0 centerline file (kind: file)."""
    path: Integer = Field(0, ge=0)
    """Which path of the q = 0 centerline file (kind: file)."""
    align_base: Flag = True
    """Place the q = 0 shape's base on the q = 1 shape's base frame."""

    # after FiniteFloat's own check, so that a nan is called not finite rather than out of range
    _length_bound = field_validator("length_mm")(size_bound(MIN_INITIAL_LENGTH_MM, MAX_INITIAL_LENGTH_MM))
    _radius_bound = field_validator("radius_mm")(size_bound(MIN_INITIAL_RADIUS_MM, MAX_INITIAL_RADIUS_MM))

    @model_validator(mode="after")
    def _kind_needs(self) -> InitialShape:
        if self.kind == "arc" and self.bend_radius_mm is None:
            raise ValueError("kind: arc needs bend_radius_mm (the arc's radius of curvature, mm)")
        if self.kind == "file" and self.centerline is None:
            raise ValueError("kind: file needs centerline (a path to the q = 0 centerline)")
        if self.radius_mm is not None and self.surface is not None:
            raise ValueError("give radius_mm or surface for the q = 0 body, not both")
        return self
