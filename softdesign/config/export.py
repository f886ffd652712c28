"""The case's ``export`` block: the meshes at each q, and its ``mould`` and ``volume_mesh`` blocks."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator, model_validator

from softdesign.config.types import CaseBlock, FiniteFloat, Flag, Integer, q_in_range
from softdesign.io.format_names import MESH_FORMATS, q_label
from softdesign.limits import MAX_ANGULAR_COUNT, MAX_EXPORT_Q
from softdesign.limits.shape import MAX_OFFSET_MM, size_bound
from softdesign.limits.volume import MAX_MESHER_SECONDS, MAX_VOLUME_MESHES, MIN_TET_SIZE_MM
from softdesign.meshing.mould.spec import MIN_MOULD_WALL_MM
from softdesign.meshing.volume_tolerance import MIN_ANGULAR_COUNT


class Mould(CaseBlock):
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


class VolumeMesh(CaseBlock):
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


class Export(CaseBlock):
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
    """Ring spacing of the meshes along l, mm: at most the fitted wall's knot spacing (the build says so before it
    meshes)."""
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
