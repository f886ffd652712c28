"""Stage 2, blend: smooth and resample the centerlines, build c(q, l) and its frames.

Kept in the build folder: ``blend/curves.npz`` (each key shape's samples at
equal arc length; the quintic spline through them is rebuilt exactly on
load) and ``blend/summary.json`` (the final path's figures and the linear
blend's shortening).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.geometry.blend import BlendedShape, BlendMode, Shortening, blend_shapes, sampled_shape
from softdesign.geometry.curve_joints import grid_with_joints
from softdesign.geometry.curves import (
    DEGREE,
    SmoothCurve,
    smooth_curve_from_polyline,
    smooth_curve_from_samples,
)
from softdesign.geometry.frames import FrameMode
from softdesign.geometry.initial import InitialSpec, build_initial_shape, initial_shape_from_polyline
from softdesign.pipeline import layout
from softdesign.pipeline.backbone_step import curve_options
from softdesign.pipeline.blend_body import body_field
from softdesign.pipeline.blend_choice import blend_notices, choose_blend, describe_choice, pcc_choice
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.design import DesignResult, load_design
from softdesign.pipeline.stages.ingest import IngestResult
from softdesign.pipeline.store import Staging, load_npz, npz_bytes

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

#: 2: the final path's torsion only where curvature >= TORSION_KAPPA_FLOOR (null when nowhere), with the
#: fraction of the path where it is defined and the floor.
#: 3: the morph's reach r * kappa over q (``morph``), ``blend: auto`` and the blend it chose.
#: 4: ``blend: pcc`` (the designed chain, each section's curvature q * kappa at constant length).
#: 5: sharp joints at explicit link breaks (``joints`` in blend/curves.npz when there are any).
#: 6: the torsion reported where the curvature is at least a fifth of its largest (TORSION_REL_FLOOR), not noise.
#: 7: ``blend: pcc`` keeps its sections' joints: each section splined on its own, every break a sample.
#: 8: ``blend: auto`` judges the fitted body over the morph, not only the inscribed radius (``body_morph``).
#: 9: ``blend: pcc`` keeps the samples its target curve was built from (it kept that curve's own points, which
#:    differ by round-off, so a loaded blend was not the one built and later stages wrote other bytes); the
#:    body's morph check on the q grid i / 40 (morph_q_grid: the last bit of 15 of its 41 q).
#: 10: ``blend: auto`` judges the body on the shape the stage keeps (rebuilt from the samples, as load_blend
#:     rebuilds it; its figures move by round-off, 1e-13), and keeps that shape with the morph's curves built.
VERSION = 10


@dataclass(frozen=True)
class BlendResult:
    """The blended shape, its figures, and the key shapes' samples it was rebuilt from (what the folder keeps)."""

    shape: BlendedShape
    summary: dict[str, Any]
    samples: tuple[np.ndarray, ...]
    #: samples where the curve keeps a corner (sharp joints at link breaks, geometry.curves)
    joints: tuple[int, ...] = ()


def run_blend(case: Case, ingest: IngestResult, design: DesignResult | None = None) -> BlendResult:
    """Build c(q, l) for the case from the ingested paths (``blend: pcc``: from the design's chain)."""
    # explicit link breaks are where a designed case's sections meet: kept sharp where the path has a corner there
    final = smooth_curve_from_polyline(ingest.path.points, curve_options(case), case.links.breaks or ())
    if case.blend == "pcc":
        if design is None:  # the case file's check refuses blend: pcc without a design: block
            raise RuntimeError("blend: pcc without a design")
        # as the design stage and load_blend build it: from the samples kept (the rebuilt curve's own points differ
        # from them by round-off, and a blend loaded from the folder must be this one, bit for bit)
        kept = final.points(final.l_grid)
        final = smooth_curve_from_samples(kept)
        shape = pcc_shape(final, design, case.frames)
        figures = pcc_choice(shape, ingest.path, design.document)
        return BlendResult(shape, {**_summary(case, shape), **figures}, (kept,))
    same_grid = curve_options(case, count=len(final.l_grid))
    spec = InitialSpec(
        kind=case.initial.kind,
        length_mm=case.initial.length_mm,
        bend_radius_mm=case.initial.bend_radius_mm,
        bend_plane_rad=float(np.deg2rad(case.initial.bend_plane_deg)),
        points=None if ingest.initial_path is None else ingest.initial_path.points,
        align_base=case.initial.align_base,
    )
    initial = build_initial_shape(final, spec, same_grid)
    # keyframes share the final shape's base point and tangent, so the actuator's base stays put
    keyframes = tuple(
        (q, initial_shape_from_polyline(final, p.points, same_grid, case.initial.align_base))
        for q, p in ingest.keyframes
    )
    # the shape rebuilt from the samples the folder keeps, as load_blend rebuilds it: the splines through them equal
    # the smoothed ones to round-off (1e-13 mm), not to the bit, and the stages after this one must get the same
    # shape whether the blend ran now or was loaded, or a stage re-run on cached results writes other bytes.
    # ``auto`` judges the body on that rebuilt shape, and the stage keeps the one it judged: the morph's curves
    # built for the judgement are the export q's (the kinematics finds them built)
    joints = final.joints

    def rebuilt(shape: BlendedShape) -> BlendedShape:
        return _shape_from_samples(shape.key_q, _samples(shape), shape.mode, shape.frames, joints)

    choice = choose_blend(initial, final, keyframes, case.blend, case.frames, ingest.path,
                          body=lambda shape: body_field(case, ingest, shape), rebuild=rebuilt)
    samples = _samples(choice.shape)
    shape = choice.judged if choice.judged is not None else rebuilt(choice.shape)
    return BlendResult(shape, {**_summary(case, shape), **choice.summary()}, samples, joints)


def _samples(shape: BlendedShape) -> tuple[np.ndarray, ...]:
    """The key curves' samples (the points each curve was built through, on its own l grid): what the folder keeps."""
    return tuple(curve.points(curve.l_grid) for curve in shape.keys)


def pcc_shape(final: SmoothCurve, design: DesignResult, frames: FrameMode) -> BlendedShape:
    """c(q, .): each designed section an arc of its own length, curvature q * kappa, plane phi, composed from the base.

    The target's l maps onto the chain by arc-length fraction (the design's breaks are the joints' fractions), so
    c(q, l) is the chain's point at arc length ``l * sum(L)``.  The samples are the target's spacing or finer, with
    every break a sample and a joint: each section is its own interpolant, so the curvature's jump between sections
    is kept, not smoothed, and a link's frames at its breaks are its section's (issue 35 item 4).
    """
    from softdesign.kinematics.pcc_chain import chain_points_at

    base, w, lengths = design.base2world, design.w, design.lengths
    l_grid, joints = grid_with_joints(design.breaks, len(final.l_grid), DEGREE)
    s = l_grid * float(np.sum(lengths))

    def sampler(q: float) -> SmoothCurve:
        return smooth_curve_from_samples(chain_points_at(base, q * w, lengths, s), joints, l_grid)

    return sampled_shape(final, sampler, "pcc", frames)


def _shape_from_samples(
    key_q: np.ndarray, samples: tuple[np.ndarray, ...], mode: BlendMode, frames: FrameMode,
    joints: tuple[int, ...] = (),
) -> BlendedShape:
    keys = [smooth_curve_from_samples(points, joints) for points in samples]
    keyframes = tuple(zip(np.asarray(key_q)[1:-1].tolist(), keys[1:-1], strict=True))
    return blend_shapes(keys[0], keys[-1], keyframes, mode, frames)


def _summary(case: Case, shape: BlendedShape) -> dict[str, Any]:
    final = shape.keys[-1].report()
    shortening = shape.shortening()
    return {
        "mode": shape.mode,
        "frames": shape.frames,
        "final_path": {
            "length_mm": final.length_mm,
            "samples": final.sample_count,
            "spacing_mm": final.spacing_mm,
            "max_curvature_per_mm": final.max_curvature_per_mm,
            "max_curvature_l": final.max_curvature_l,
            "max_abs_torsion_per_mm": final.max_abs_torsion_per_mm,
            "max_abs_torsion_l": final.max_abs_torsion_l,
            "torsion_defined_fraction": final.torsion_defined_fraction,
            "torsion_kappa_floor_per_mm": final.torsion_floor_per_mm,
        },
        "initial_length_mm": shape.keys[0].length,
        "shortening": {
            "q_at_min": shortening.q_at_min,
            "min_length_mm": shortening.min_length_mm,
            "reference_length_mm": shortening.reference_length_mm,
            "ratio": shortening.ratio,
        },
    }


def write_blend(result: BlendResult, staging: Staging) -> None:
    """Keep the key shapes' samples (``pcc``: the final shape's; the chain is the design's) and the figures."""
    samples = {f"key_{k}": points for k, points in enumerate(result.samples)}
    key_q = result.shape.key_q if result.shape.mode != "pcc" else np.array([1.0])
    joints = {"joints": np.asarray(result.joints, np.int64)} if result.joints else {}  # none: the bytes of before
    staging.write_bytes(layout.BLEND_CURVES, npz_bytes(key_q=key_q, **samples, **joints))
    staging.write_json(layout.BLEND_SUMMARY, result.summary)


def load_blend(build_dir: Path) -> BlendResult:
    """Rebuild the blended shape from the kept samples (no smoothing is redone)."""
    data = load_npz(Path(build_dir) / layout.BLEND_CURVES)
    summary = json.loads((Path(build_dir) / layout.BLEND_SUMMARY).read_text(encoding="utf-8"))
    samples = tuple(data[f"key_{k}"] for k in range(len(data["key_q"])))
    if summary["mode"] == "pcc":
        design = load_design(build_dir)
        if design is None:
            raise ConfigError(f"{build_dir}: blend: pcc was built from a design, but design/summary.json is missing; "
                              "run `softdesign build` again")
        return BlendResult(pcc_shape(smooth_curve_from_samples(samples[0]), design, summary["frames"]), summary,
                           samples)
    joints = tuple(int(j) for j in data.get("joints", np.zeros(0, np.int64)))
    shape = _shape_from_samples(data["key_q"], samples, summary["mode"], summary["frames"], joints)
    return BlendResult(shape, summary, samples, joints)


def torsion_text(path: dict[str, Any]) -> str:
    """Max |torsion| and where it is defined (curvature above the floor), or that it is undefined everywhere."""
    floor, fraction = path["torsion_kappa_floor_per_mm"], path["torsion_defined_fraction"]
    if path["max_abs_torsion_per_mm"] is None:
        return f"torsion undefined (curvature below {floor:g} /mm everywhere)"
    where = "" if fraction == 1.0 else f" on {100 * fraction:.1f}% of the path; undefined elsewhere"
    return f"max |torsion| {path['max_abs_torsion_per_mm']:.4f} /mm (where curvature >= {floor:g} /mm{where})"


def describe_blend(result: BlendResult) -> list[str]:
    """Human summary lines."""
    s = result.summary
    f = s["final_path"]
    lines = [
        f"final path: {f['length_mm']:.2f} mm, {f['samples']} samples every {f['spacing_mm']:.3f} mm, "
        f"max curvature {f['max_curvature_per_mm']:.4f} /mm, {torsion_text(f)}",
        f"blend {s['mode']}, frames {s['frames']}; initial length {s['initial_length_mm']:.2f} mm",
    ]
    sh = Shortening(**s["shortening"])
    if sh.intermediate_is_shorter:
        lines.append(
            f"shortest shape: {sh.min_length_mm:.2f} mm at q = {sh.q_at_min:.3f}, {100 * sh.ratio:.3g}% shorter "
            f"than the shorter end shape ({sh.reference_length_mm:.2f} mm)"
        )
    else:
        lines.append(
            f"no intermediate shape is shorter than both end shapes (q = 0: {s['initial_length_mm']:.2f} mm, "
            f"q = 1: {f['length_mm']:.2f} mm)"
        )
    if result.joints:
        grid = result.shape.keys[-1].l_grid
        at = ", ".join(f"{grid[j]:.4f}" for j in result.joints)
        lines.append(f"sharp joints (link breaks at a corner of the path, not smoothed over) at l = {at}")
    return lines + describe_choice(s)


STAGE = Stage(
    name="blend",
    version=VERSION,
    # blend: auto fits the wall, with the links' breaks and the fit's settings, to judge the body's morph
    reads=("initial", "resample", "frames", "blend", "links", "fit"),
    upstream=("ingest", "design"),
    compute=lambda case, results: run_blend(case, results["ingest"], results.get("design")),
    write=write_blend,
    load=lambda build_dir, results: load_blend(build_dir),
    describe=describe_blend,
    metrics=lambda result: result.summary,
    warnings=lambda result: blend_notices(result.summary),
)
