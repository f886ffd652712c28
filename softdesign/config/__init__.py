"""The case file: YAML -> validated models, defaults filled in, paths resolved.

A case file is YAML validated by pydantic models that forbid unknown keys.
Errors are reported with the file, the line, the dotted field, what was
expected and what was found; an unknown key gets the nearest valid key as a
suggestion.  Relative paths are relative to the case file.  ``units`` names
the unit of the *input files* (and of ``final.inlet``); everything inside
softdesign is millimetres, the conversion happens at ingest.
"""

from __future__ import annotations

import difflib
import math
import os
import re
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from softdesign.config.actuation import Actuation, single_supply_problems
from softdesign.config.design import Design, pcc_blend_problems
from softdesign.config.fit_caps import MAX_LOCAL_CAPS, LocalMaxRadius
from softdesign.config.material import CustomMaterial
from softdesign.config.simulate import Simulate
from softdesign.config.types import FiniteFloat, Flag, Integer, q_in_range
from softdesign.errors import ConfigError
from softdesign.io.case_yaml import parse_case_yaml, read_case_text
from softdesign.io.format_names import MESH_FORMATS, q_label
from softdesign.limits import (
    MAX_ANGULAR_COUNT,
    MAX_ANGULAR_INTERVALS,
    MAX_CURVE_SAMPLES,
    MAX_EXPORT_Q,
    MAX_HOLDOUT_FOLDS,
    MAX_LINKS,
    MEMORY_BUDGET_TEXT,
)
from softdesign.limits.shape import (
    MAX_INITIAL_LENGTH_MM,
    MAX_INITIAL_RADIUS_MM,
    MAX_OFFSET_MM,
    MIN_INITIAL_LENGTH_MM,
    MIN_INITIAL_RADIUS_MM,
    size_bound,
)
from softdesign.limits.volume import MAX_MESHER_SECONDS, MAX_VOLUME_MESHES, MIN_TET_SIZE_MM
from softdesign.materials import MaterialLimits, PresetName, resolve_material
from softdesign.meshing.mould.spec import MIN_MOULD_WALL_MM
from softdesign.meshing.volume_tolerance import (
    MAX_CAVITY_SHARE,
    MIN_ANGULAR_COUNT,
    MIN_ANGULAR_COUNT_WITH_CAVITIES,
    VOLUME_RTOL,
)


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)


class FinalShape(_Section):
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


class IntermediateShape(_Section):
    """A keyframe centerline reached at ``q`` (piecewise-linear in q between keyframes)."""

    q: FiniteFloat = Field(gt=0.0, lt=1.0)
    """The q at which this keyframe is reached, strictly between 0 and 1."""
    centerline: Path
    """The keyframe's centerline file."""
    path: Integer = Field(0, ge=0)
    """Which path of the keyframe's centerline file."""
    reverse: Flag = False
    """Flip the keyframe path's orientation."""


class InitialShape(_Section):
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


class Resample(_Section):
    """Arc-length resampling and smoothing of every centerline."""

    spacing_mm: FiniteFloat = Field(0.5, gt=0.0)
    """Arc length between resampled points, mm."""
    count: Integer | None = Field(None, ge=4, le=MAX_CURVE_SAMPLES)
    """A fixed number of resampled points instead of spacing_mm."""
    smoothing_mm: FiniteFloat = Field(0.1, ge=0.0)
    """Smoothing of the centerline (Gaussian width along arc length), mm; 0 keeps it as it is."""
    end_straight_mm: FiniteFloat = Field(2.0, ge=0.0)
    """Straighten this much of each end, mm (a centerline's last points bend towards the cap)."""

    @model_validator(mode="after")
    def _one_rule(self) -> Resample:
        if self.count is not None and "spacing_mm" in self.model_fields_set:  # count would win silently
            raise ValueError("give one of count, spacing_mm; got both")
        return self


class Links(_Section):
    """How the actuator is split into links: exactly one of the three keys."""

    count: Integer | None = Field(None, ge=1, le=MAX_LINKS)
    """The number of links of equal length."""
    breaks: list[FiniteFloat] | None = Field(None, max_length=MAX_LINKS + 1)
    """Link breaks in normalized l, from 0 to 1, strictly increasing."""
    length_mm: FiniteFloat | None = Field(None, gt=0.0)
    """Links of about this length, mm."""

    @model_validator(mode="after")
    def _one_rule(self) -> Links:
        given = [k for k in ("count", "breaks", "length_mm") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"give one of count, breaks, length_mm; got {', '.join(given)}")
        if not given:
            raise ValueError("give one of count, breaks (normalized l), length_mm")
        if self.breaks is not None:
            _check_breaks(self.breaks)
        return self


def _check_breaks(breaks: list[float]) -> None:
    if len(breaks) < 2 or breaks[0] != 0.0 or breaks[-1] != 1.0:
        raise ValueError(f"breaks must start at 0 and end at 1 (normalized l), got {breaks}")
    if any(nxt <= prev for prev, nxt in zip(breaks[:-1], breaks[1:], strict=True)):
        raise ValueError(f"breaks must be strictly increasing, got {breaks}")


#: The largest fit.end_margin_mm (a path's end cap region is a few millimetres; ingest also keeps it within a
#: quarter of the path's length, pipeline/bounds.py).
MAX_END_MARGIN_MM = 20.0


class Fit(_Section):
    """Least-squares spline surface rho(l, a) per link."""

    # defaults measured on the VMTK aorta (mean edge 0.97 mm): 1.5 mm x 24 keeps ~3 points per
    # coefficient; 1e-5 is the least penalty that bridges the other iliac's opening; the aorta's
    # elliptical inlet wall reaches 1.79x the inscribed radius, so outliers start at 2x
    knot_spacing_mm: float | Literal["auto"] = 1.5
    """Knot spacing of the spline along l, mm, or auto."""
    angular_intervals: Integer = Field(24, ge=4, le=MAX_ANGULAR_INTERVALS)
    """Knot intervals of the spline around the body."""
    smoothing: FiniteFloat = Field(1.0e-5, ge=0.0)
    """Weight of the smoothing penalty of the least-squares fit."""
    holdout_folds: Integer = Field(5, ge=2, le=MAX_HOLDOUT_FOLDS)
    """Folds of the k-fold hold-out error of the fit."""
    outlier_factor: FiniteFloat = Field(2.0, gt=1.0)
    """A wall point beyond this factor (or its inverse) of the reference radius is an outlier."""
    # wall points within this of either end are not fitted (a tilted cap's rim, one-sided ends); the end's
    # rings are then held at the inscribed radius by the end prior (fitting/end_prior.py)
    end_margin_mm: FiniteFloat = Field(0.0, ge=0.0, le=MAX_END_MARGIN_MM)
    """Wall points within this of either end are not fitted; the end's rings are held at the inscribed radius, mm."""
    # where the body ends: at each end's detected cap plane or boundary loop (auto, cap_plane) or square to the
    # end tangent (normal); see geometry/end_cut.py
    end_cut: Literal["auto", "cap_plane", "normal"] = "auto"
    """Where the body ends: auto (at a detected cap plane or open loop, else square), cap_plane, or normal (square to
    the end tangent).
    """
    # the body's radius is held at most this along the whole path (a thinner body makes a turn the vessel's
    # width cannot: a branch's take-off); a fold's message offers the value (fitting/radius_field.py)
    max_radius_mm: FiniteFloat | None = Field(None, gt=0.0)
    """A cap on the fitted body's radius, mm: a thinner body that can make a turn tighter than the vessel is wide (the
    fix a fold's message names).
    """
    # the same cap over stretches of the path only, tapering back to the fit (config/fit_caps.py)
    local_max_radius: list[LocalMaxRadius] = Field(default_factory=list, max_length=MAX_LOCAL_CAPS)
    """Caps on the body's radius over stretches of the path only, each {from_mm, to_mm, radius_mm, taper_mm} (the fix
    a fold at a take-off offers first).
    """

    @field_validator("knot_spacing_mm", mode="before")
    @classmethod
    def _spacing(cls, value: Any) -> Any:
        if value == "auto":
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"must be a number of mm or 'auto', got {value!r}")
        if not math.isfinite(value):
            raise ValueError(f"must be a finite number of mm or 'auto', got {value}")
        if value <= 0:
            raise ValueError(f"must be > 0 mm, got {value}")
        return float(value)


class Mould(_Section):
    """A two-part casting mould around the body at q = 0 (and a core for a hollow body): every size in mm."""

    margin_mm: FiniteFloat = Field(10.0, gt=0.0, le=200.0)
    """Mould material around the body, mm."""
    clearance_mm: FiniteFloat = Field(0.2, ge=0.0, le=5.0)
    """Clearance of the keys and core prints, mm."""
    key_mm: FiniteFloat = Field(4.0, gt=0.0, le=100.0)
    """Size of the registration keys between the halves, mm."""
    pour_mm: FiniteFloat = Field(4.0, gt=0.0, le=50.0)
    """Diameter of the pour channel, mm."""
    vent_mm: FiniteFloat = Field(2.0, gt=0.0, le=50.0)
    """Diameter of the vent, mm."""
    print_mm: FiniteFloat = Field(10.0, gt=0.0, le=200.0)
    """Length of the core prints that hold a core, mm."""
    #: casting orientation: which end of the body is up (the pour and vent enter at the top)
    up: Literal["base", "tip"] = "base"
    """Which end of the body is up when cast (the pour and vent enter at the top)."""

    @model_validator(mode="after")
    def _keys_fit(self) -> Mould:
        # the keys sit margin_mm / 2 beside the body (softdesign.meshing.mould.parts), a wall from the cavity
        need = 2.0 * (0.5 * self.key_mm + self.clearance_mm + MIN_MOULD_WALL_MM)
        if self.margin_mm < need:
            raise ValueError(
                f"a key of key_mm={self.key_mm:g} with clearance_mm={self.clearance_mm:g} needs margin_mm >= {need:g} "
                f"(keys sit margin_mm / 2 beside the body, {MIN_MOULD_WALL_MM:g} mm of mould from the cavity), got "
                f"{self.margin_mm:g}; raise margin_mm or lower key_mm"
            )
        return self


class VolumeMesh(_Section):
    """Tetrahedral meshes of the body for simulators: sizes in mm."""

    #: sweep: one mesh made in the body's parameter domain, mapped to every q (deterministic, named surfaces);
    #: ftetwild: fTetWild on each q's surface in a child process
    mesher: Literal["sweep", "ftetwild"] = "sweep"
    """sweep (the body's own parameter-domain mesh, the same at every q) or ftetwild (fTetWild in a child process)."""
    #: the q values to mesh: [0] (the state the actuator is cast in, which a simulator deforms) by default
    q: list[FiniteFloat] = Field([0.0], min_length=1, max_length=MAX_VOLUME_MESHES)
    """The q values to mesh (default [0], the state the actuator is cast in)."""
    #: target edge length of the tetrahedra (sweep: the largest edge inside the section, pi D / size_mm nodes on a
    #: chamber's or feed's circle, and the layers' spacing along the body, halved where it would invert a
    #: tetrahedron or miss the volume; its skin's nodes are on the export's angles)
    size_mm: FiniteFloat = Field(2.0, ge=MIN_TET_SIZE_MM, le=50.0)
    """Target edge length of the tetrahedra, mm."""
    #: largest distance of the mesh's boundary from the body's surface
    envelope_mm: FiniteFloat = Field(0.05, ge=0.001, le=1.0)
    """Largest distance of the mesh's boundary from the body's surface, mm (ftetwild)."""
    #: the mesher is stopped after this long (per q) and the build fails with a clear message
    timeout_s: FiniteFloat = Field(1800.0, gt=0.0, le=MAX_MESHER_SECONDS)
    """The mesher is stopped after this long per q, s, and the build fails with a clear message."""

    @field_validator("q")
    @classmethod
    def _q_in_range(cls, values: list[float]) -> list[float]:
        q_in_range(values)
        labels = [q_label(v) for v in values]
        if len(set(labels)) != len(labels):
            raise ValueError(f"give each q once, at least 0.001 apart (files are named with three decimals), "
                             f"got {values}")
        return sorted(values)


class Export(_Section):
    """Meshes at the requested q values."""

    q: list[FiniteFloat] | None = Field(None, max_length=MAX_EXPORT_Q)
    """The q values to export, each in [0, 1], at least 0.001 apart (default [0, 0.5, 1])."""
    frames: Integer | None = Field(None, ge=2, le=MAX_EXPORT_Q)
    """Instead of q: this many q values evenly spaced from 0 to 1."""
    offset_mm: FiniteFloat = 0.0
    """Move the whole skin outwards (+) or inwards (-) from the fitted wall, mm."""
    wall_mm: FiniteFloat | None = Field(None, gt=0.0)
    """Make the body hollow: one chamber that follows the skin, with walls and end caps this thick, mm."""
    port_mm: FiniteFloat | None = Field(None, gt=0.0)
    """The diameter of a port through the base cap into the chamber, mm (needs wall_mm)."""
    # the names come from io.formats' registry (one list); mypy cannot read a Literal built from a tuple at run time
    formats: list[Literal[MESH_FORMATS]] = Field(["stl"], min_length=1)  # type: ignore[valid-type]
    """Mesh formats: stl ply obj glb vtp (ply and vtp carry each face's region)."""
    spacing_mm: FiniteFloat = Field(0.5, gt=0.0)
    """Ring spacing of the meshes along l, mm."""
    _offset_bound = field_validator("offset_mm")(size_bound(-MAX_OFFSET_MM, MAX_OFFSET_MM))
    angular_count: Integer = Field(64, ge=MIN_ANGULAR_COUNT, le=MAX_ANGULAR_COUNT)
    """Vertices around each ring of the meshes."""
    #: also write one STL per face region (wall, caps, chamber, port): meshes/q_0.500/wall.stl, ...
    split_regions: Flag = False
    """Also write one STL per face region (wall, caps, chamber, port)."""
    frame: Literal["patient", "base"] = "patient"
    """The output meshes' coordinates: patient (the input files', over the vessel) or base (the q = 0 body's base
    at the origin, z along its axis, for printing and CAD); the manifest records the move."""
    #: a casting mould of the body at q = 0: meshes/mould/{half_a,half_b,core}.stl (the mould stage)
    mould: Mould | None = None
    """A two-part casting mould of the body at q = 0 (the mould stage)."""
    #: tetrahedral meshes of the body for simulators: meshes/volume/q_0.000.{vtu,msh} (the volume_mesh stage)
    volume_mesh: VolumeMesh | None = None
    """Volume meshes of the body for simulators, with named surfaces (the volume_mesh stage)."""

    @field_validator("q")
    @classmethod
    def _q_names_differ(cls, values: list[float] | None) -> list[float] | None:
        # a mesh is named by its q with three decimals (meshes/q_0.500.stl, DESIGN.md): two q values that
        # print alike would write one file, and one of the two meshes would be lost without a word
        seen: dict[str, float] = {}
        for q in values or []:
            name = q_label(q)
            if name in seen:
                what = f"{q!r} is listed twice" if seen[name] == q else (
                    f"{seen[name]!r} and {q!r} both name their mesh {name}.stl (q has three decimals in file names)")
                raise ValueError(f"{what}; give each q once, the values at least 0.001 apart (e.g. 0.5 and 0.501)")
            seen[name] = q
        return values

    @model_validator(mode="after")
    def _q_values(self) -> Export:
        if self.q is not None and self.frames is not None:
            raise ValueError("give q (a list) or frames (a count), not both")
        if self.port_mm is not None and self.wall_mm is None:
            raise ValueError("port_mm needs wall_mm (a port opens into the hollow chamber)")
        if self.mould is not None and self.wall_mm is not None and self.port_mm is None:
            raise ValueError("mould of a hollow body needs port_mm: a sealed chamber cannot be cast around a core "
                             "(the core is held and removed through the port)")
        if self.q is not None:
            bad = [v for v in self.q if not 0.0 <= v <= 1.0]
            if bad or not self.q:
                raise ValueError(f"q values must lie in [0, 1], got {self.q}")
        return self

    def q_values(self) -> list[float]:
        """The export q values, sorted and unique; default [0, 0.5, 1]."""
        if self.frames is not None:
            return [i / (self.frames - 1) for i in range(self.frames)]
        return sorted(set(self.q if self.q is not None else [0.0, 0.5, 1.0]))


class Material(_Section):
    """Limits the design is judged against: a preset (``name``) and/or explicit numbers, which win."""

    name: PresetName | None = None
    """A preset (softdesign materials lists them with their sources)."""
    #: a material of the user's own, every figure given (softdesign/config/material.py); not with ``name``
    custom: CustomMaterial | None = None
    """Your own material: every key required."""
    max_stretch: float | None = Field(None, gt=1.0, le=100.0)
    """The largest principal stretch allowed (overrides the preset's)."""
    min_stretch: float | None = Field(None, gt=0.0, lt=1.0)
    """The smallest principal stretch allowed before a thin skin wrinkles (overrides the preset's)."""
    min_wall_mm: float | None = Field(None, gt=0.0, le=100.0)
    """The thinnest wall allowed, mm (overrides the preset's)."""

    @model_validator(mode="after")
    def _one_source(self) -> Material:
        if self.name is not None and self.custom is not None:
            raise ValueError("give name (a preset) or custom (your own material), not both")
        return self

    def limits(self) -> MaterialLimits:
        """The preset's (or the custom material's) numbers with the explicit ones put over them."""
        explicit = (self.max_stretch, self.min_stretch, self.min_wall_mm)
        if self.custom is None:
            return resolve_material(self.name, *explicit)
        base = self.custom.limits()
        return replace(base, max_stretch=self.max_stretch or base.max_stretch, min_stretch=self.min_stretch,
                       min_wall_mm=self.min_wall_mm)


class Case(_Section):
    """A whole case file, every default filled in."""

    name: str
    """The case's name: letters, digits, '-' and '_' (default: the case file's stem); the build folder is build/<name>.
    """
    units: Literal["mm", "cm", "m"] = "mm"
    """The unit of the input files and of final.inlet: mm, cm or m; everything is converted to mm at ingest."""
    final: FinalShape
    """The patient's shape, q = 1: the vessel's centerline and surface as VMTK exports them."""
    initial: InitialShape = InitialShape()
    """The insertion shape, q = 0, and the body's radius there."""
    intermediate: list[IntermediateShape] = []
    """Keyframe centerlines reached at given q between 0 and 1 (the morph is piecewise between them)."""
    resample: Resample = Resample()
    """Arc-length resampling and smoothing of every centerline."""
    frames: Literal["rmf", "frenet"] = "rmf"
    """The frames along each centerline: rmf (rotation-minimizing, defined on straight runs) or frenet (Awasthi et
    al.'s; undefined where the curvature vanishes).
    """
    blend: Literal["auto", "linear", "intrinsic", "pcc"] = "auto"
    """How c(q, l) morphs from q = 0 to q = 1: auto (linear unless its intermediate shapes fold), linear (Awasthi et
    al.'s), intrinsic (length-preserving) or pcc (each designed section bends at constant length; needs design:).
    """
    #: the composed-chain design stage (between ingest and blend); blend: pcc morphs its chain
    design: Design | None = None
    """Design the actuator as a chain of constant-curvature sections composed from the base (the design stage;
    softdesign design).
    """
    links: Links = Links(count=4)
    """How the body is split into links (sections): exactly one of count, breaks, length_mm."""
    fit: Fit = Fit()
    """The least-squares spline surface rho(l, angle) fitted to the vessel wall, per link."""
    export: Export = Export()
    """The meshes written at each q, their format and resolution, and the hollow, mould and volume-mesh options."""
    #: no material: the feasibility figures are reported and judged against nothing
    material: Material | None = None
    """The material the design is judged against: a preset and/or explicit limits (the verdict of the report)."""
    #: seed 003's three chambers per section with their feed lines, built into the body (issue 31)
    actuation: Actuation | None = None
    """Chambers cut into the body: Zou et al.'s three per section with a feed each, or one per section on one supply."""
    #: chamber pressures per section and q by finite elements in the build (the simulate stage; issue 33)
    simulate: Simulate | None = None
    """Estimate each section's chamber pressures for given q in the build (finite elements; off unless enabled)."""

    _base: Path = PrivateAttr(default_factory=Path.cwd)

    @model_validator(mode="after")
    def _pcc_needs_a_design(self) -> Case:
        problems = pcc_blend_problems(self.blend, self.design, self.initial.kind, len(self.intermediate))
        problems += single_supply_problems(self.actuation, self.blend, self.design is not None,
                                           self.export.mould is not None, self.export.volume_mesh is not None)
        if problems:
            raise ValueError("; ".join(problems))
        return self

    @field_validator("frames")
    @classmethod
    def _frenet_needs_curvature(cls, frames: str, info: ValidationInfo) -> str:
        """Refuse ``frames: frenet`` where a shape is straight by construction: the frame is undefined there.

        A straight q = 0 shape has no curvature anywhere, and ``resample.end_straight_mm > 0``
        asks for straight ends on every shape; the build would stop at the kinematics stage
        (curvature below FRENET_KAPPA_TOL, or a frame flip where the curvature passes through
        zero).  ``initial`` and ``resample`` come before ``frames``, so pydantic has validated
        them; a section that failed its own checks is absent from ``info.data`` and not judged.
        """
        initial, resample = info.data.get("initial"), info.data.get("resample")
        if not (isinstance(initial, InitialShape) and initial.kind == "straight"):
            initial = None  # judged only when it is a straight initial shape
        if not (isinstance(resample, Resample) and resample.end_straight_mm > 0.0):
            resample = None  # judged only when it asks for straight ends
        if frames != "frenet" or (initial is None and resample is None):
            return frames
        problems, fixes = [], []
        if initial is not None:
            default = "" if "kind" in initial.model_fields_set else " (the default)"
            problems.append(f"initial.kind: straight{default} makes the q = 0 shape a straight line")
            fixes.append("initial.kind: arc (with initial.bend_radius_mm)")
        if resample is not None:
            default = "" if "end_straight_mm" in resample.model_fields_set else " (the default)"
            problems.append(
                f"resample.end_straight_mm: {resample.end_straight_mm:g}{default} makes the last "
                f"{resample.end_straight_mm:g} mm at both ends of every shape straight"
            )
            fixes.append("resample.end_straight_mm: 0")
        raise ValueError(
            "frenet needs curvature everywhere, but " + " and ".join(problems) + "; the Frenet normal is "
            "undefined where the curvature is zero. Use frames: rmf (defined on straight parts) or set "
            + " and ".join(fixes)
        )

    @field_validator("export")
    @classmethod
    def _mould_casts_square_ends(cls, export: Export, info: ValidationInfo) -> Export:
        """Refuse ``fit.end_cut: cap_plane`` with ``export.mould``: a two-part mould cannot release a cap plane
        leaning out of its parting plane.

        ``auto`` turns each cut into the parting plane when a mould is asked for (and says by how much);
        ``cap_plane`` asks for the detected plane itself.
        """
        fit = info.data.get("fit")
        if export.mould is not None and isinstance(fit, Fit) and fit.end_cut == "cap_plane":
            raise ValueError(
                "export.mould's two halves cannot be drawn off a cap plane that leans out of their parting plane, "
                "and fit.end_cut: cap_plane cuts the exported body at the detected cap plane itself; use "
                "fit.end_cut: auto (each cut turned into the parting plane) or normal (square ends) with a mould, "
                "or drop export.mould"
            )
        return export

    @field_validator("actuation")
    @classmethod
    def _one_kind_of_cavity(cls, actuation: Actuation | None, info: ValidationInfo) -> Actuation | None:
        export = info.data.get("export")
        if actuation is None:  # a default is not validated: only a key given as null (a bare `actuation:`) is
            raise ValueError("is empty (a bare `actuation:` line), which would mean no chambers; write "
                             "`actuation: {}` for the default chambers, or remove the line for a body without them")
        if isinstance(export, Export) and export.angular_count < MIN_ANGULAR_COUNT_WITH_CAVITIES:
            raise ValueError(f"needs export.angular_count of at least {MIN_ANGULAR_COUNT_WITH_CAVITIES}, got "
                             f"{export.angular_count}: the chambers leave less solid to hold the body polygon's "
                             "missing area, and the mesh volume check fails (up to "
                             f"{MAX_CAVITY_SHARE:.0%} of a section in chambers and feeds); raise "
                             f"export.angular_count to {MIN_ANGULAR_COUNT_WITH_CAVITIES}")
        if isinstance(export, Export) and export.wall_mm is not None:
            raise ValueError("actuation's chambers and export.wall_mm's single hollow chamber are two designs of "
                             "the cavity; drop export.wall_mm (and port_mm) or drop actuation")
        return actuation

    @field_validator("simulate")
    @classmethod
    def _simulate_needs_chambers(cls, simulate: Simulate | None, info: ValidationInfo) -> Simulate | None:
        if simulate is not None and simulate.enabled and info.data.get("actuation") is None:
            raise ValueError("simulate.enabled solves the actuation chambers' pressures; add an actuation: block "
                             "(and a material:) or set enabled: false")
        return simulate

    @field_validator("name")
    @classmethod
    def _name_is_a_slug(cls, value: str) -> str:
        # the name becomes a folder (build/<name>) and the stem of names beside it: a name, never a path
        if re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9._-]{0,99}", value) is None:
            example = re.sub(r"[^A-Za-z0-9._-]+", "-", value).lstrip(".-")[:100] or "demo"
            raise ValueError(
                f"must be a name, not a path: 1 to 100 letters, digits, '-', '_' or '.', not starting with '.', "
                f"got {value!r}; write e.g. name: {example} (the default is the case file's name without .yaml)"
            )
        return value

    @property
    def base_dir(self) -> Path:
        """The folder of the case file; relative input paths start here."""
        return self._base

    def resolved_path(self, path: Path) -> str:
        """``path`` relative to the case file's folder, POSIX style (for outputs)."""
        return Path(os.path.relpath(path, self._base)).as_posix()

    def resolved(self) -> dict[str, Any]:
        """The case as a JSON-ready dict, defaults filled in, for the build folder.

        Input paths are written relative to the case file's folder so that the
        same case built from another checkout gives the same bytes.
        """
        return _relative_paths(self.model_dump(mode="json"), self._base)


def load_case(path: str | Path) -> Case:
    """Read, validate and resolve a case file.

    Raises
    ------
    ConfigError
        The file is missing or unreadable, is not valid YAML, or does not
        match the schema; the message names the file, line and field.
    """
    path = Path(path)
    raw, root = _parse_yaml(path, read_case_text(path))
    raw.setdefault("name", path.stem)
    try:
        case = Case.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(_format_errors(path, root, err)) from None
    return _resolve_paths(case, path.resolve().parent)


def _parse_yaml(path: Path, text: str) -> tuple[dict[str, Any], yaml.Node | None]:
    raw, root = parse_case_yaml(path, text)
    if not isinstance(raw, dict):
        raise ConfigError(
            f"{path}: expected a mapping of keys (name, units, final, ...), "
            f"got {type(raw).__name__}; see configs/demo.yaml for an example"
        )
    return raw, root


def _resolve_paths(case: Case, base: Path) -> Case:
    def full(p: Path | None) -> Path | None:
        return None if p is None else (p if p.is_absolute() else base / p)

    def full_or_auto(p: Path | Literal["auto"]) -> Path | Literal["auto"]:
        if isinstance(p, str):  # "auto": extracted from the surface at ingest
            return p
        return p if p.is_absolute() else base / p

    final = case.final.model_copy(
        update={"centerline": full_or_auto(case.final.centerline), "surface": full(case.final.surface)}
    )
    initial = case.initial.model_copy(
        update={"centerline": full(case.initial.centerline), "surface": full(case.initial.surface)}
    )
    inter = [s.model_copy(update={"centerline": full(s.centerline)}) for s in case.intermediate]
    resolved = case.model_copy(update={"final": final, "initial": initial, "intermediate": inter})
    resolved._base = base
    return resolved


def _relative_paths(data: Any, base: Path) -> Any:
    if isinstance(data, dict):
        return {k: _relative_paths(v, base) for k, v in data.items()}
    if isinstance(data, list):
        return [_relative_paths(v, base) for v in data]
    if isinstance(data, str) and os.path.isabs(data):
        return Path(os.path.relpath(data, base)).as_posix()
    return data


# --- error messages ---------------------------------------------------------------

_TEMPLATES = {
    "greater_than": "must be > {gt}",
    "greater_than_equal": "must be >= {ge}",
    "less_than": "must be < {lt}",
    "less_than_equal": "must be <= {le}",
    "missing": "is required",
    "finite_number": "must be a finite number (not NaN, inf, or too large for a float)",
    "int_type": "must be a whole number written as one (e.g. 4; not true/false, 4.0, 1e6 or a string)",
    "too_long": "has more than {max_length} entries (the limit)",
}
#: Keys whose upper bound is a limit of softdesign.limits (what it protects, for the message).
_LIMITED = {
    "resample.count", "links.count", "links.breaks", "fit.angular_intervals", "fit.holdout_folds",
    "export.q", "export.frames", "export.angular_count",
}
#: Longest shown input value in a message, characters (a value of megabytes would make a message of megabytes).
_SHOWN_CHARS = 200


def _format_errors(path: Path, root: yaml.Node | None, err: ValidationError) -> str:
    lines = [f"{path}: the case file is invalid ({err.error_count()} problem(s)):"]
    for item in err.errors():
        loc = tuple(item["loc"])
        line = _line_of(root, loc)
        where = f"{path}:{line}" if line else str(path)
        lines.append(f"  {where}: {_describe(loc, item)}")
    lines.append("Fix the listed keys; `softdesign validate CASE.yaml` re-checks without building.")
    return "\n".join(lines)


#: Why a range holds, added to its message (dotted field -> reason).
_RANGE_REASONS = {
    "export.angular_count": (
        f"fewer vertices around cannot pass the mesh volume check (a {MIN_ANGULAR_COUNT - 1}-gon already misses "
        f"more than {100 * VOLUME_RTOL:g}% of a round section's area)"
    ),
}


def _describe(loc: tuple[Any, ...], item: Mapping[str, Any]) -> str:
    field = ".".join(str(p) for p in loc) or "(top level)"
    kind = item["type"]
    if kind == "extra_forbidden":
        return _unknown_key(loc)
    ctx = item.get("ctx") or {}
    if kind in _TEMPLATES:
        text = _TEMPLATES[kind].format(**ctx)
    else:
        text = item["msg"].removeprefix("Value error, ")
        if text.startswith("Input should be"):
            text = "should be" + text[len("Input should be") :]
    # a model-level rule names its keys and quotes the values in its own message
    if kind == "value_error":
        return f"{field}: {text}"
    got = "" if kind == "missing" else f", got {_shown(item.get('input'))}"
    reason = f": {_RANGE_REASONS[field]}" if field in _RANGE_REASONS and kind in _TEMPLATES else ""
    if field in _LIMITED and kind in ("less_than_equal", "too_long"):
        reason = f": a limit of softdesign/limits/__init__.py that keeps a build within {MEMORY_BUDGET_TEXT} of memory"
    return f"{field} {text}{got}{reason}"


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= _SHOWN_CHARS else f"{text[:_SHOWN_CHARS]}... ({len(text)} characters)"


def _unknown_key(loc: tuple[Any, ...]) -> str:
    model: type[BaseModel] = Case
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        ann = model.model_fields[str(part)].annotation
        model = next((a for a in _model_args(ann)), model)
    valid = sorted(model.model_fields)
    key = str(loc[-1])
    near = difflib.get_close_matches(key, valid, n=1, cutoff=0.5)
    parent = ".".join(str(p) for p in loc[:-1]) or "the top level"
    hint = f"did you mean '{near[0]}'? " if near else ""
    return f"unknown key '{key}' in {parent}; {hint}valid keys: {', '.join(valid)}"


def _model_args(ann: Any) -> list[type[BaseModel]]:
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return [ann]
    found: list[type[BaseModel]] = []
    for arg in getattr(ann, "__args__", ()):
        found.extend(_model_args(arg))
    return found


def _line_of(root: yaml.Node | None, loc: tuple[Any, ...]) -> int | None:
    """1-based line of the YAML node at ``loc`` (or of its deepest existing parent)."""
    node, line = root, None
    for part in loc:
        if isinstance(node, yaml.MappingNode):
            match = next(((k, v) for k, v in node.value if k.value == str(part)), None)
            if match is None:
                break
            line = match[0].start_mark.line + 1
            node = match[1]
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and part < len(node.value):
            node = node.value[part]
            line = node.start_mark.line + 1
        else:
            break
    return line
