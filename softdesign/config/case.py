"""The whole case file: the ``Case`` model over every block, and :func:`load_case` (YAML -> validated,
resolved case).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import PrivateAttr, ValidationError, ValidationInfo, field_validator, model_validator

from softdesign.config.actuation import Actuation, single_supply_problems
from softdesign.config.design import Design, pcc_blend_problems
from softdesign.config.export import Export
from softdesign.config.fit import Fit
from softdesign.config.links import Links
from softdesign.config.material import Material
from softdesign.config.messages import format_errors
from softdesign.config.resample import Resample
from softdesign.config.shapes import FinalShape, InitialShape, IntermediateShape
from softdesign.config.simulate import Simulate
from softdesign.config.types import CaseBlock
from softdesign.errors import ConfigError
from softdesign.io.case_yaml import case_text_record, parse_case_yaml, read_case_text
from softdesign.meshing.volume_tolerance import MAX_CAVITY_SHARE, MIN_ANGULAR_COUNT_WITH_CAVITIES


class Case(CaseBlock):
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
    _source: dict[str, str] | None = PrivateAttr(default=None)

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

    @property
    def chamber_ends(self) -> str:
        """``actuation.reinforcement.ends``: bare or patch (bare for a case without an ``actuation:`` block)."""
        return "bare" if self.actuation is None else self.actuation.reinforcement.ends

    @property
    def source(self) -> dict[str, str] | None:
        """The case file it was read from: ``{"name": file name, "sha256": of its text}`` (None when not read from a
        file).  ``softdesign pressure`` answers from a build without building the case's models when both match."""
        return self._source

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
    text = read_case_text(path)
    raw, root = _parse_yaml(path, text)
    raw.setdefault("name", path.stem)
    try:
        case = Case.model_validate(raw)
    except ValidationError as err:
        raise ConfigError(format_errors(path, root, err, Case)) from None
    resolved = _resolve_paths(case, path.resolve().parent)
    resolved._source = case_text_record(path, text)
    return resolved


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
