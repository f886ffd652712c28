"""Stage 4, kinematics: the links' S_T_E(q) and POE form at every export q.

``kinematics.json`` (at the top of the build folder) holds, per export q and
per link, the transform S_T_E = inv(F(q, l_s)) F(q, l_e) (4x4, mm), its POE
split, the link's arc length, stretch and curvature range, and the chain's
base_to_tip.  A ``blend: pcc`` build (the design's chain) adds per pose the
design's sections at that q with seed 003's improved-D-H rows
(``pcc_sections``).  Conventions are written into the file itself.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.geometry.frames import FramedSpline
from softdesign.kinematics import pcc
from softdesign.kinematics.arc_check import arc_check_metrics, arc_misses, link_arcs_at_final_shape
from softdesign.kinematics.arc_tolerance import ARC_TOLERANCE_MM
from softdesign.kinematics.links import LinkChain, LinkReport
from softdesign.kinematics.poe import PoeSplit
from softdesign.pipeline import layout
from softdesign.pipeline.notices import Notice
from softdesign.pipeline.parallel import map_per_q
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.design import DesignResult
from softdesign.pipeline.stages.links import LinksResult
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

VERSION = 3  # 2: blend: pcc builds carry the design's sections at each pose (pcc_sections, pcc_convention)
#            3: the conventions cite their paper
CONVENTION = (
    "F(q, l) = [[N B T c], [0 0 0 1]]; transform = S_T_E = inv(F(q, l_start)) F(q, l_end), "
    "mapping end-frame coordinates into start-frame coordinates; "
    "S_T_E = exp(xi1 theta1) exp(omega theta2): translation theta1 (mm) along unit xi1 (in {S}), "
    "then rotation theta2 in [0, pi] (rad) about unit omega (null when theta2 = 0); "
    "base_to_tip = product of the link transforms in link order (the tip frame in link 1's {S})"
)
#: The pcc_sections of a blend: pcc build (written only there).
PCC_CONVENTION = (
    "blend: pcc: each pose's pcc_sections are the design's sections (design/summary.json) at the pose's q of their "
    "link: an arc of curvature q * kappa, plane phi and length L; transform is the section's HTM (its tip frame in "
    "its base frame, Zou et al.: Rz(phi) Ry(theta/2) Tz(chord) Ry(theta/2) Rz(-phi)) and dh its rows (dh: "
    + pcc.DH_CONVENTION + "); the links' transforms are measured on the built centerline's frames, which follow "
    "the chain as resampled"
)


@dataclass(frozen=True)
class KinematicsResult:
    """The link chain and the JSON document kept in the build folder."""

    chain: LinkChain
    document: dict[str, Any]


def poe_dict(split: PoeSplit) -> dict[str, Any]:
    """The POE split as JSON (axes as lists, null when undefined)."""
    return {
        "theta1": split.theta1,
        "xi1": None if split.xi1 is None else np.asarray(split.xi1).tolist(),
        "theta2": split.theta2,
        "omega": None if split.omega is None else np.asarray(split.omega).tolist(),
    }


def link_dict(report: LinkReport) -> dict[str, Any]:
    """One link at one q as JSON."""
    return {
        "index": report.index,
        "q": report.q,
        "l_start": report.l_start,
        "l_end": report.l_end,
        "length": report.length_mm,
        "transform": report.transform.tolist(),
        "poe": poe_dict(report.poe),
        "stretch": [report.stats.stretch_min, report.stats.stretch_max],
        "curvature_per_mm": [report.stats.curvature_min_per_mm, report.stats.curvature_max_per_mm],
    }


def pose_document(chain: LinkChain, q: float | list[float]) -> dict[str, Any]:
    """Links, base_to_tip and base_to_world of the chain at one q (or one q per link)."""
    q_links = chain.q_per_link(q)
    reports = chain.reports(q_links)
    tip2base = np.eye(4)
    for report in reports:
        tip2base = tip2base @ report.transform
    return {
        "q": q_links.tolist(),
        "links": [link_dict(r) for r in reports],
        "base_to_tip": tip2base.tolist(),
        "base_to_world": chain.base2world(q_links).tolist(),
    }


def shape_figures(chain: LinkChain, q: float) -> dict[str, Any]:
    """The whole centerline at q: length, stretch range, max curvature, largest frame step."""
    curve = chain.shape.curve_at(q)  # builds the frames: a flip or an undefined Frenet frame fails here
    stats = chain.shape.stats_at(q)
    return {
        "q": q,
        "length_mm": stats.length_mm,
        "stretch_min": stats.stretch_min,
        "stretch_max": stats.stretch_max,
        "curvature_max_per_mm": stats.curvature_max_per_mm,
        "max_frame_step_rad": curve.max_frame_step,
    }


def _at_q(chain: LinkChain, q: float, built: bool = False
          ) -> tuple[dict[str, Any], dict[str, Any], FramedSpline | None]:
    """The shape's figures and the pose at q, and the framed curve built for them (to keep in the build process;
    None when ``built``: the build process has it already)."""
    return shape_figures(chain, q), pose_document(chain, q), None if built else chain.shape.curve_at(q)


def run_kinematics(case: Case, links: LinksResult, design: DesignResult | None = None) -> KinematicsResult:
    """Link transforms and POE at every export q (one q per worker process at a time, results in q order).

    A ``blend: pcc`` chain (its links are the design's sections) adds the sections' arcs, HTMs and D-H rows.
    """
    chain = links.chain
    q_values = case.export.q_values()
    built = {q for q in q_values if chain.shape.built_curve(q) is not None}  # the blend's judgement of the body
    per_q = map_per_q(lambda q: _at_q(chain, q, q in built), q_values)
    for q, (_, _, curve) in zip(q_values, per_q, strict=True):
        if curve is not None:
            chain.shape.keep_curve(q, curve)  # export and feasibility then use them, as when built here
    poses = [pose for _, pose, _ in per_q]
    pcc_design = design if chain.shape.mode == "pcc" else None  # the chain's links are its sections
    if pcc_design is not None:
        for pose in poses:
            pose["pcc_sections"] = pcc_design.sections_at(pose["q"])
    document: dict[str, Any] = {
        "frames": case.frames,
        "convention": CONVENTION,
        "units": {"length": "mm", "angle": "rad"},
        "links": [
            {"index": j, "l_start": float(chain.breaks[j]), "l_end": float(chain.breaks[j + 1])}
            for j in range(chain.count)
        ],
        "per_q": [figures for figures, _, _ in per_q],
        "poses": poses,
        **({"pcc_convention": PCC_CONVENTION} if pcc_design is not None else {}),
    }
    return KinematicsResult(chain, document)


def write_kinematics(result: KinematicsResult, staging: Staging) -> None:
    """Write ``kinematics.json``."""
    staging.write_json(layout.KINEMATICS, result.document)


def load_kinematics(build_dir: Path, links: LinksResult) -> KinematicsResult:
    """The document from disk, on the (already loaded) chain of links."""
    document = json.loads((Path(build_dir) / layout.KINEMATICS).read_text(encoding="utf-8"))
    return KinematicsResult(links.chain, document)


def describe_kinematics(result: KinematicsResult) -> list[str]:
    """One line per export q and link."""
    lines = [f"{len(result.document['links'])} link(s), frames {result.document['frames']}"]
    for row in result.document["per_q"]:
        lines.append(
            f"  q = {row['q']:.3f}: length {row['length_mm']:.2f} mm, stretch {row['stretch_min']:.4f}"
            f"..{row['stretch_max']:.4f}, max curvature {row['curvature_max_per_mm']:.4f} /mm, "
            f"largest frame step {math.degrees(row['max_frame_step_rad']):.2e} deg"
        )
    for pose in result.document["poses"]:
        for link in pose["links"]:
            p = link["poe"]
            lines.append(
                f"  q = {link['q']:.3f} link {link['index']}: length {link['length']:.2f} mm, "
                f"theta1 {p['theta1']:.3f} mm, theta2 {math.degrees(p['theta2']):.3f} deg, "
                f"stretch {link['stretch'][0]:.3f}..{link['stretch'][1]:.3f}"
            )
    return lines  # the links one arc cannot make: :func:`kinematics_notices`


def kinematics_notices(result: KinematicsResult) -> list[Notice]:
    """One warning per link whose q = 1 centerline one constant-curvature arc misses by more than the tolerance."""
    arcs = link_arcs_at_final_shape(result.chain)
    misses = [j for j, arc in enumerate(arcs) if arc.max_deviation_mm > ARC_TOLERANCE_MM]
    return [Notice("kinematics", "arc_misfit", f"link {j}", text)
            for j, text in zip(misses, arc_misses(arcs), strict=True)]


STAGE = Stage(
    name="kinematics",
    version=VERSION,
    reads=("frames", "export.q", "export.frames"),
    upstream=("links", "design"),
    compute=lambda case, results: run_kinematics(case, results["links"], results["design"]),
    write=write_kinematics,
    load=lambda build_dir, results: load_kinematics(build_dir, results["links"]),
    describe=describe_kinematics,
    metrics=lambda result: {"links": len(result.document["links"]), "file": layout.KINEMATICS,
                            "arc_check": arc_check_metrics(result.chain)},
    warnings=kinematics_notices,
)
