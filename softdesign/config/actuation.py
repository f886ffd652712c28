"""The case file's ``actuation:`` block: the chambers, their supply, reinforcement and backbone.

``supply: per_chamber`` (the default, Zou et al.'s device: three chambers per
section, one feed each, the sizes below) or ``single`` (one chamber per
section, sized and tapered by the rod model so that one design pressure bends
every section into its designed arc: :mod:`softdesign.kinematics.rod_sizing`;
it needs ``design:`` and ``blend: pcc``).  ``per_chamber`` stays the default
so that a case written before round 4 builds the device it describes.

``reinforcement`` defaults to ``hoop``: without it a chamber balloons and, in
an incompressible body, its side-wall pressure cancels the end caps' moment
(kappa = (1 - 2 nu) P A d / (E I) = 0, issue 41); cast three-chamber arms wind
a thread round each core (Pagliarani et al., Actuators 2023, cotton thread in
Ecoflex 00-50) or sheathe them in a braid (STIFF-FLOP).  The default thread is
``kevlar-69`` (softdesign/data/threads.yaml, its sources there), at a pitch of
0.5 mm: below a chamber's radius (0.3-1 mm here), so the silicone between two
turns cannot bulge (the rod model's assumption), and a safety factor of 4 on
the thread's straight breaking load (a wound, knotted thread keeps about half
of it, and half again for the cycling: a stated rule of thumb, not a datum).

``backbone`` defaults to ``inextensible`` (a thread cast along the axis): the
length then stays the designed one at every pressure, so the morph is exactly
``blend: pcc``'s, each tapered section an exact arc, and the body is cast at
the length the build meshes.  ``free`` lets the pressure stretch each section
too; along a tapered section the stretch varies with the area, so a section
is an arc only approximately, and its cast length must be shorter than the
vessel's path (the build reports both).

Per-chamber sizes:

Sizes are absolute millimetres, not fractions of the local radius: Zou et al.'s
inverse (three lengths -> kappa, phi, L) takes one chamber distance ``d`` per
section, and the relation ``l_j = L - kappa L d cos(beta_j - phi)`` holds only
when the chamber runs at a constant distance from the backbone.  A fraction of
a radius that changes along the vessel (2.9 to 3.7 mm on the demo) would bend
each chamber away from that offset curve, make the mould's straight pins
impossible, and break the round trip through ``pcc reconstruct``.  The vessel
enters through the layout check instead: the build refuses a layout whose walls
do not fit the thinnest section, with the largest diameter that would.

The defaults fit the demo (radius 2.9-3.7 mm, four sections, nine feeds through
the first): ring at 2.0 mm, chambers 0.8 mm, feeds 0.4 mm, leaving 0.5 mm of
skin over a chamber, 0.44 mm between a chamber and a feed and 0.64 mm between
two feeds (30 degrees apart on the ring).  ``first_angle_deg`` 90 puts section 1's
chamber 1 where Zou et al.'s encoder 1 sits (90 degrees from N).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from softdesign.config.types import FiniteFloat, Integer

if TYPE_CHECKING:  # numpy stays out of `softdesign validate`
    from softdesign.meshing.chambers.layout import ActuationSpec

#: The largest size any actuation key takes, mm (a vessel is at most 20 mm in median radius, limits at ingest).
MAX_ACTUATION_MM = 50.0


#: The largest pitch of a hoop winding, mm (a turn per 10 mm no longer holds a sub-millimetre chamber).
MAX_PITCH_MM = 10.0
#: The largest safety factor on the thread's breaking load.
MAX_SAFETY_FACTOR = 100.0
#: Keys that ``supply: single`` sizes itself (a value given for them would be ignored).
SIZED_BY_SINGLE = ("chambers_per_section", "distance_mm", "diameter_mm", "first_angle_deg")


class ThreadChoice(BaseModel):
    """A thread of softdesign/data/threads.yaml, by name."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = "kevlar-69"
    """The thread's name in softdesign/data/threads.yaml (``softdesign materials`` lists them)."""

    @field_validator("name")
    @classmethod
    def _known(cls, name: str) -> str:
        from softdesign.materials.threads import thread_presets

        if name not in thread_presets():
            raise ValueError(f"unknown thread {name!r}; choose one of {', '.join(sorted(thread_presets()))}")
        return name


class Reinforcement(BaseModel):
    """What stops a chamber's radial growth: a thread wound round it (``hoop``), or nothing (``none``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: Literal["hoop", "none"] = "hoop"
    """hoop: a thread wound round each chamber core before casting; none: bare chambers (no rod-model bend)."""
    pitch_mm: FiniteFloat = Field(0.5, gt=0.0, le=MAX_PITCH_MM)
    """Distance between two turns of the winding, mm."""
    thread: ThreadChoice = ThreadChoice()
    """The thread (hoops and the inextensible backbone)."""
    safety_factor: FiniteFloat = Field(4.0, ge=1.0, le=MAX_SAFETY_FACTOR)
    """A turn's tension may reach the thread's breaking load over this factor."""
    ends: Literal["bare", "patch"] = "bare"
    """bare: a chamber's flat ends are silicone alone; patch: a disc woven of the thread (two crossed layers at the
    pitch) on each end of a chamber core (the FE models it; the rod model does not need it)."""


class Actuation(BaseModel):
    """The chambers in the body: their supply, reinforcement and backbone, and Zou et al.'s per-chamber sizes."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    supply: Literal["single", "per_chamber"] = "per_chamber"
    """single: one pressure, one sized chamber per section; per_chamber: Zou et al.'s three chambers, a feed each."""
    reinforcement: Reinforcement = Reinforcement()
    """The hoop winding round each chamber (or none)."""
    backbone: Literal["free", "inextensible"] = "inextensible"
    """inextensible: a thread along the axis keeps the length; free: pressure also stretches each section."""

    chambers_per_section: Integer = Field(3, ge=3, le=3)
    """Chambers in each section (Zou et al.'s three)."""
    distance_mm: FiniteFloat = Field(2.0, gt=0.0, le=MAX_ACTUATION_MM)
    """Distance of the chambers' axes from the backbone, mm (absolute: Zou et al.'s d is one number per section)."""
    diameter_mm: FiniteFloat = Field(0.8, gt=0.0, le=MAX_ACTUATION_MM)
    """Diameter of each chamber, mm."""
    feed_diameter_mm: FiniteFloat = Field(0.4, gt=0.0, le=MAX_ACTUATION_MM)
    """Diameter of each chamber's feed line, mm."""
    end_wall_mm: FiniteFloat = Field(1.0, gt=0.0, le=MAX_ACTUATION_MM)
    """Wall at each end of a chamber, mm, along the centerline: more than a slanted end face (fit.end_cut) reaches
    over an end chamber (the build names the value before it meshes)."""
    first_angle_deg: FiniteFloat = Field(90.0, ge=-360.0, le=360.0)
    """Angle of the first chamber from the section's base N, degrees (Zou et al.'s first encoder is at 90)."""

    @model_validator(mode="after")
    def _chambers_fit_their_ring(self) -> Actuation:
        if self.supply == "single":
            given = [k for k in SIZED_BY_SINGLE if k in self.model_fields_set]
            if given:
                raise ValueError(f"supply: single sizes {', '.join(given)} itself (the rod model); remove "
                                 f"{'it' if len(given) == 1 else 'them'}, or use supply: per_chamber")
            return self
        d, big = self.distance_mm, self.diameter_mm
        if self.feed_diameter_mm > big:
            raise ValueError(
                f"feed_diameter_mm {self.feed_diameter_mm:g} is wider than diameter_mm {big:g}: a feed enters its "
                f"chamber along its axis and must be no wider; use feed_diameter_mm <= {big:g}"
            )
        if big >= 2.0 * d:
            raise ValueError(
                f"diameter_mm {big:g} reaches across the backbone from distance_mm {d:g} (needs diameter < 2 x "
                f"distance = {2 * d:g}); use a smaller diameter or a larger distance"
            )
        between = 2.0 * d * math.sin(math.pi / 3.0)
        if big >= between:
            raise ValueError(
                f"three chambers of diameter_mm {big:g} at distance_mm {d:g} overlap (centres {between:.3f} mm "
                f"apart, 2 d sin 60 deg); use diameter_mm < {between:.3f} or a larger distance"
            )
        return self

    def spec(self) -> ActuationSpec:
        """The layout's numbers."""
        from softdesign.meshing.chambers.layout import ActuationSpec

        return ActuationSpec(self.distance_mm, self.diameter_mm, self.feed_diameter_mm, self.end_wall_mm,
                             self.first_angle_deg, self.chambers_per_section)


def single_supply_problems(actuation: Actuation | None, blend: str, designed: bool, mould: bool,
                           volume_mesh: bool) -> list[str]:
    """Why ``supply: single`` cannot build this case (empty when it can): it sizes each designed arc, and its
    tapered chambers, joined in series, are not yet in the volume mesh.  The mould casts them on one lost core
    (:mod:`softdesign.meshing.mould.cores`): ``mould`` is no longer a problem."""
    if actuation is None or actuation.supply != "single":
        return []
    mould = False  # the mould casts them (one lost core): only the volume mesh below is still refused
    problems = []
    if not designed or blend != "pcc":
        problems.append("actuation.supply: single sizes one chamber per designed constant-curvature section and "
                        "morphs as blend: pcc; add design: {tolerance_mm: 1} and blend: pcc (or use supply: "
                        "per_chamber)")
    for wanted, key in ((mould, "export.mould"), (volume_mesh, "export.volume_mesh")):
        if wanted:
            problems.append(f"{key} does not take actuation.supply: single's tapered chambers joined in series yet "
                            f"(cast them on lost wax cores as actuation/summary.json gives them); drop {key} or use "
                            "supply: per_chamber")
    return problems
