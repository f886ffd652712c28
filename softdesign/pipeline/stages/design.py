"""Stage design (between ingest and blend): sections of constant curvature composed from the base frame (issue 30).

Runs when the case has a ``design:`` block (else it computes and writes
nothing).  The target is the q = 1 centerline as the blend smooths and
resamples it, with rotation-minimizing frames from the blend's base normal;
the core is :mod:`softdesign.kinematics.chain_design`.

Kept in the build folder: ``design/summary.json`` (:func:`design_document`,
what ``softdesign design --json`` prints: per section its arc and seed 003's
improved-D-H rows) and ``design/profile.npz`` (the deviation along l and the
chain's points, for the report).

For other stages and helpers: :func:`load_design` gives a :class:`DesignResult`
whose :meth:`DesignResult.sections` lists each section's l range, kappa,
phi, L, theta and base and tip frames (4x4, world), and
:meth:`DesignResult.sections_at` the sections at one q per section as
``blend: pcc`` bends them (their HTMs and D-H rows, for kinematics.json).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError
from softdesign.geometry.curves import SmoothCurve, smooth_curve_from_polyline, smooth_curve_from_samples
from softdesign.geometry.frames import base_normal_from_tangent, framed_curve
from softdesign.kinematics import pcc
from softdesign.kinematics.chain_design import METHOD, ChainOptions, ChainTarget, design_chain
from softdesign.kinematics.pcc_chain import arcs_from_w, dense_chain_points, section_poses
from softdesign.pipeline import layout
from softdesign.pipeline.backbone_step import curve_options
from softdesign.pipeline.notices import Notice
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.ingest import IngestResult
from softdesign.pipeline.stages.judges import design_judgement
from softdesign.pipeline.store import Staging, load_npz, npz_bytes
from softdesign.types import FloatArray, Pose

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

VERSION = 3  # 2: each section's D-H rows (dh) and the dh_convention in design/summary.json; 3: its papers cited
#: Below this bending angle (rad) a section is reported straight: kappa and phi 0 (phi is rounding noise there).
STRAIGHT_THETA_RAD = 1e-9
#: Spacing of the chain's points kept for the report, mm.
PROFILE_STEP_MM = 0.25

CONVENTION = (
    "mm, radians (phi, theta) and degrees only where a key says _deg. Section 1 starts on base_frame (4x4, world: "
    "columns N, B, T and the position of the q = 1 centerline at l = 0, rotation-minimizing frames); each next "
    "section starts on the previous tip_frame (Zou et al.'s improved D-H). phi is measured in the section's base frame "
    "from N towards B, and the section bends towards phi; kappa >= 0, theta = kappa * length; a straight section has "
    "kappa = phi = 0. l_start, l_end are normalized l of the q = 1 centerline, at the joints' arc-length fractions of "
    "the chain. max_deviation_mm: the largest true distance between the composed chain and the centerline, both "
    "ways (target samples to the chain, chain points to the centerline); tip_error_mm: chain tip to the "
    "centerline's end; tip_error_deg: angle between their tangents. dh: the section's five improved D-H rows "
    "(dh_convention), whose product is the section's transform inv(base frame) @ tip_frame"
)


@dataclass(frozen=True)
class Section:
    """One designed section: l range (normalized l of the target), arc (1/mm, rad, mm, rad), frames (4, 4) world."""

    index: int
    l_start: float
    l_end: float
    kappa: float
    phi: float
    length: float
    theta: float
    base_frame: Pose
    tip_frame: Pose
    max_deviation_mm: float


@dataclass(frozen=True)
class DesignResult:
    """The design's document (:func:`design_document`) and the profile arrays for the report."""

    document: dict[str, Any]
    profile: dict[str, np.ndarray]

    @property
    def base2world(self) -> Pose:
        """(4, 4) where section 1 starts."""
        return np.array(self.document["base_frame"], float)

    @property
    def w(self) -> FloatArray:
        """(k, 2) 1/mm curvature vectors ``kappa (cos phi, sin phi)``."""
        links = self.document["links"]
        return np.array([[k["kappa"] * np.cos(k["phi"]), k["kappa"] * np.sin(k["phi"])] for k in links])

    @property
    def lengths(self) -> FloatArray:
        """(k,) mm."""
        return np.array([k["length"] for k in self.document["links"]], float)

    @property
    def breaks(self) -> FloatArray:
        """(k + 1,) normalized l of the target."""
        return np.array(self.document["breaks"], float)

    def sections(self) -> list[Section]:
        """Every section, proximal first."""
        bases, _ = section_poses(self.base2world, self.w, self.lengths)
        return [Section(k["index"], k["l_start"], k["l_end"], k["kappa"], k["phi"], k["length"], k["theta"],
                        bases[j], np.array(k["tip_frame"], float), k["max_deviation_mm"])
                for j, k in enumerate(self.document["links"])]

    def sections_at(self, q: npt.ArrayLike) -> list[dict[str, Any]]:
        """Every section at its q (one per section) as ``blend: pcc`` bends it: curvature q * kappa, plane phi, L.

        Each is ``{"index", "q", "kappa", "phi", "length", "theta", "dh", "transform"}``: the arc
        (:func:`arc_document`) and its HTM (4x4, the section's tip in its base frame, seed 003).
        """
        q = np.broadcast_to(np.asarray(q, float), self.lengths.shape)
        sections = []
        for j, link in enumerate(self.document["links"]):
            arc = arc_document(float(q[j]) * link["kappa"], link["phi"], link["length"])
            transform = pcc.transform_from_arc(arc["kappa"], arc["phi"], arc["length"]) + 0.0  # -0.0 written as 0.0
            sections.append({"index": link["index"], "q": float(q[j]), **arc, "transform": transform.tolist()})
        return sections


def arc_document(kappa: float, phi: float, length: float) -> dict[str, Any]:
    """One section's ``kappa, phi, length, theta`` (1/mm, rad, mm, rad) and seed 003's D-H rows ``dh``.

    Below :data:`STRAIGHT_THETA_RAD` of bending a section is straight: kappa = phi = 0.
    """
    straight = kappa * length < STRAIGHT_THETA_RAD
    kappa, phi = (0.0, 0.0) if straight else (float(kappa), float(phi))
    return {"kappa": kappa, "phi": phi, "length": float(length), "theta": kappa * float(length),
            "dh": pcc.dh_rows(kappa, phi, float(length))}


def final_curve(case: Case, ingest: IngestResult) -> SmoothCurve:
    """The q = 1 centerline exactly as the blend stage builds it (smoothed, resampled, rebuilt from its samples)."""
    smooth = smooth_curve_from_polyline(ingest.path.points, curve_options(case))
    return smooth_curve_from_samples(smooth.points(smooth.l_grid))


def chain_target(curve: SmoothCurve) -> ChainTarget:
    """The core's target: samples, rotation-minimizing frames (the blend's base normal), arc length, dense polyline."""
    normal = base_normal_from_tangent(curve.tangents([0.0])[0])
    framed = framed_curve(curve, "rmf", normal, label="design target (q = 1)")
    l = curve.l_grid
    return ChainTarget(curve.points(l), framed.frames(l), l * curve.length, curve.points(curve.dense_l()))


def chain_options(case: Case, ingest: IngestResult) -> ChainOptions:
    """The case's ``design:`` bounds; the shortest section defaults to the vessel's median inscribed diameter."""
    design = case.design
    if design is None:
        raise ConfigError("design: the case has no design: block")
    shortest = design.min_link_mm
    if shortest is None:
        radius = ingest.path.radius
        if radius is None or not len(radius):
            raise ConfigError("design.min_link_mm: the centerline carries no radius (MaximumInscribedSphereRadius), "
                              "so the default shortest section (the vessel's median diameter) is unknown; give "
                              "design.min_link_mm (or --min-link-mm)")
        shortest = float(2.0 * np.median(radius))
    tip = design.tip_tolerance_mm if design.tip_tolerance_mm is not None else design.tolerance_mm
    return ChainOptions(design.tolerance_mm, tip, design.tip_tolerance_deg, shortest, design.max_links)


def run_design(case: Case, ingest: IngestResult) -> DesignResult | None:
    """The composed-chain design of the case's q = 1 centerline, or None without a ``design:`` block."""
    if case.design is None:
        return None
    curve = final_curve(case, ingest)
    target = chain_target(curve)
    options = chain_options(case, ingest)
    chain = design_chain(target, options)
    document = design_document(chain, options)
    points, s = dense_chain_points(chain.base2world, chain.w, chain.length, PROFILE_STEP_MM)
    profile = {"l": curve.l_grid, "deviation_mm": chain.target_deviation_mm, "target_points": target.points,
               "chain_points": points, "chain_s": s}
    return DesignResult(document, profile)


def design_document(chain: Any, options: ChainOptions) -> dict[str, Any]:
    """The JSON document of a :class:`~softdesign.kinematics.chain_design.ChainDesign` (see ``CONVENTION``)."""
    kappa, phi = arcs_from_w(chain.w)
    links = [{"index": j, "l_start": float(chain.breaks[j]), "l_end": float(chain.breaks[j + 1]),
              **arc_document(float(kappa[j]), float(phi[j]), float(chain.length[j])),
              "tip_frame": chain.tips[j].tolist(), "max_deviation_mm": float(chain.section_deviation_mm[j])}
             for j in range(len(chain.length))]
    return {
        "tolerance_mm": options.tolerance_mm,
        "tip_tolerance_mm": options.tip_tolerance_mm,
        "tip_tolerance_deg": options.tip_tolerance_deg,
        "min_link_mm": options.min_link_mm,
        "max_links": options.max_links,
        "meets_tolerance": bool(chain.meets),
        "chain_max_deviation_mm": chain.chain_max_deviation_mm,
        "tip_error_mm": chain.tip_error_mm,
        "tip_error_deg": chain.tip_error_deg,
        "base_frame": np.asarray(chain.base2world, float).tolist(),
        "links": links,
        "breaks": [float(b) for b in chain.breaks],
        "searched": [{"links": k, "worst_mm": worst} for k, worst in chain.tried],
        "method": METHOD,
        "convention": CONVENTION,
        "dh_convention": pcc.DH_CONVENTION,
    }


def write_design(result: DesignResult | None, staging: Staging) -> None:
    """Keep the document and the profile (nothing without a design)."""
    if result is None:
        return
    staging.write_json(layout.DESIGN_SUMMARY, result.document)
    staging.write_bytes(layout.DESIGN_PROFILE, npz_bytes(**result.profile))


def load_design(build_dir: Path) -> DesignResult | None:
    """The design kept in ``build_dir``, or None when the build had none."""
    summary = Path(build_dir) / layout.DESIGN_SUMMARY
    if not summary.is_file():
        return None
    document = json.loads(summary.read_text(encoding="utf-8"))
    return DesignResult(document, load_npz(Path(build_dir) / layout.DESIGN_PROFILE))


def miss_text(document: dict[str, Any]) -> str | None:
    """The warning when a design misses its bounds, else None."""
    if document["meets_tolerance"]:
        return None
    angle = "" if document["tip_tolerance_deg"] is None else f", {document['tip_tolerance_deg']:g} deg"
    return (f"the design misses its bounds: {len(document['links'])} section(s) (design.max_links "
            f"{document['max_links']}) leave the composed chain up to {document['chain_max_deviation_mm']:.3g} mm "
            f"from the centerline (design.tolerance_mm {document['tolerance_mm']:g}) with the tip "
            f"{document['tip_error_mm']:.3g} mm, {document['tip_error_deg']:.3g} deg off (tip bounds "
            f"{document['tip_tolerance_mm']:g} mm{angle}); raise design.max_links or the tolerances, or lower "
            "design.min_link_mm")


def describe_design(result: DesignResult | None) -> list[str]:
    """Human summary lines."""
    if result is None:
        return ["no design: in the case file: no composed-chain design (softdesign design CASE --tolerance-mm T)"]
    d = result.document
    lines = [f"{len(d['links'])} section(s) composed from the base: chain within {d['chain_max_deviation_mm']:.3g} mm "
             f"of the q = 1 centerline (tolerance {d['tolerance_mm']:g} mm), tip off by {d['tip_error_mm']:.3g} mm "
             f"and {d['tip_error_deg']:.3g} deg"]
    return lines  # a miss of its bounds: :func:`design_notices`


def design_notices(result: DesignResult | None) -> list[Notice]:
    """A warning when the design misses its bounds."""
    miss = None if result is None else miss_text(result.document)
    return [] if miss is None else [Notice("design", "design_miss", "", miss)]


def design_metrics(result: DesignResult | None) -> dict[str, Any]:
    """The manifest's design figures (null without a design)."""
    if result is None:
        return {"designed": False}
    d = result.document
    return {"designed": True, "links": len(d["links"]), "meets_tolerance": d["meets_tolerance"],
            "chain_max_deviation_mm": d["chain_max_deviation_mm"], "tip_error_mm": d["tip_error_mm"],
            "tip_error_deg": d["tip_error_deg"], "breaks": d["breaks"]}


STAGE = Stage(
    name="design",
    version=VERSION,
    reads=("design", "resample"),
    upstream=("ingest",),
    compute=lambda case, results: run_design(case, results["ingest"]),
    write=write_design,
    load=lambda build_dir, results: load_design(build_dir),
    describe=describe_design,
    metrics=design_metrics,
    warnings=design_notices,
    judge=lambda result: design_judgement(None if result is None else result.document),
)
