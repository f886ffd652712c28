"""Stage 5, fit: the wall's rho(l, a) per link at q = 1, its quality, and the radius field rho(q).

Kept in the build folder: ``fit/surface.npz`` (the radius field: per link
knots, final and initial coefficients), ``fit/points.npz`` (every projected
surface point with its selection reason, residual and, where the metrics
measured it, true distance to the fitted surface, for reports) and
``fit/summary.json`` (counts, settings, true-distance metrics, hold-out,
joint jumps, rho * kappa at q = 1).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError, FitError, FoldError
from softdesign.fitting.bspline_surface import FitSettings, fit_radius_surface
from softdesign.fitting.local_cap import check_caps_on_path
from softdesign.fitting.mapping import mapped_blocks
from softdesign.fitting.morph_folds import fold_over_morph, fold_over_morph_from, morph_grid
from softdesign.fitting.projection import PROJECT_BLOCK, project_points
from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.selection import NetworkContext, inscribed_profile
from softdesign.fitting.wall_fit import FIT_STEPS, fit_wall
from softdesign.geometry.curves import SmoothCurve, measure_deviation
from softdesign.geometry.end_cut import choose_end_cuts
from softdesign.geometry.morph_fold import morph_q_grid
from softdesign.geometry.network import SelectedPath
from softdesign.kinematics.links import LinkChain
from softdesign.meshing.mould.frame import parting_frame
from softdesign.pipeline import layout
from softdesign.pipeline.backbone_step import describe_backbone_fit, stretch_fit_errors
from softdesign.pipeline.blend_body import known_projection
from softdesign.pipeline.fit_options import wall_fit_options
from softdesign.pipeline.fold_paths import with_avoiding_paths
from softdesign.pipeline.item_progress import step_counter
from softdesign.pipeline.parallel import map_items
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.fit_notices import fit_notices
from softdesign.pipeline.stages.ingest import IngestResult
from softdesign.pipeline.stages.links import LinksResult
from softdesign.pipeline.store import Staging, load_npz, npz_bytes
from softdesign.types import FloatArray

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

VERSION = 11  # 2: flat-cap points and too-small rho excluded; hold-out sampled above 200k points
# 3: points fitted in path order; distances sampled above 200k points (max still over all)
# 4: end prior and end radii (issue 20); true distances on the regularized backbone's stretches (``backbone``)
# 5: each end's cut plane in the end frame (``end_cut``, issue 20)
# 6: fit/points.npz keeps the true distance of every point the metrics measured (``distance``, NaN elsewhere)
# 7: the fit against all of the path's own wall, its coverage and flags (``all_wall``, ``coverage``, issue 29)
# 8: the coverage warnings in an engineer's words (issue 44)
# 9: fit.local_max_radius, and the all-wall figures outside its stretches (issue 43)
# 10: above 200k kept points the spline is fitted to an even subset, and the all-wall figures are sampled by
#     stratum from the kept points' distances (issue 46); fewer points fit and measure as before
# 11: the morph's q grid i / 40 (morph_q_grid), so the export q's curves and fold reports are reused, not rebuilt
#: Seed of the hold-out folds: the same case always gets the same folds.
HOLDOUT_SEED = 4
#: A failed fit is blamed on the centerline when the smoothed one strays from the input by this fraction of the
#: smallest radius: on the demo the default smoothing strays 3% and fits, resample.smoothing_mm 2 strays 91% and fails.
STRAY_FRACTION = 0.25
#: Points of the q = 0 centerline the mould's parting plane is found from (a straight one needs two; a curved
#: one keeps its ends square with a mould, see :func:`_parting_local`).
PARTING_SAMPLES = 65


@dataclass(frozen=True)
class FitResult:
    """The radius field and the figures of the fit."""

    field: RadiusField
    summary: dict[str, Any]
    points: dict[str, np.ndarray]


def _parting_local(chain: LinkChain) -> FloatArray | None:
    """The mould's parting-plane normal in the q = 0 end frames' (N, B, T) coordinates, (2, 3); None for a
    curved q = 0 body (see :func:`~softdesign.geometry.end_cut.choose_end_cuts`)."""
    start = chain.shape.curve_at(0.0)
    frames = start.frames(np.array([0.0, 1.0]))
    frame = parting_frame(start.points(np.linspace(0.0, 1.0, PARTING_SAMPLES)), frames[0])
    if not frame.straight:
        return None
    return np.einsum("kji,j->ki", frames, frame.axes[2])


def run_fit(case: Case, ingest: IngestResult, links: LinksResult) -> FitResult:
    """Fit the wall of the selected path and build rho(q) for every link."""
    if len(ingest.faces) == 0:
        raise ConfigError("final.surface is required to fit the actuator's surface; add it to the case file")
    chain = links.chain
    curve = chain.shape.target_curve()  # the vessel's centerline (blend: pcc carries the wall onto the chain)
    path = ingest.path
    inscribed = (None, None) if path.radius is None else inscribed_profile(curve, path.points, path.radius)
    network = NetworkContext(path.points, tuple(p.points for p in ingest.others), *inscribed)
    fit = case.fit
    options = wall_fit_options(case, tuple(chain.breaks), map_items)  # the hold-out's folds on the build's workers
    options = replace(options, progress=step_counter("fit", FIT_STEPS))  # a bar on a terminal
    q_grid = morph_q_grid()
    if ingest.initial_surface is None:  # the body is the wall's field: its morph's grid joins the hold-out's pool
        options = replace(options, with_field=lambda field: _morph_job(chain, field, q_grid))
    # the rows blend: auto's look at the body projected on this curve are not projected again
    options = replace(options, known_projection=known_projection(chain.shape, ingest.vertices, curve))
    problems = check_caps_on_path(options.local_caps, curve.length)
    if problems:
        raise ConfigError(f"{problems[0]}; move or remove that entry")
    try:
        wall = fit_wall(curve, ingest.vertices, network, options, np.random.default_rng(HOLDOUT_SEED))
    except FoldError as err:  # the paths that avoid the take-off, beside the caps the fit offers
        raise with_avoiding_paths(err, curve, ingest.others) from err
    except FitError as err:
        stray = centerline_stray(case, curve.curve, path)
        if stray is None or isinstance(err, FoldError):  # a fold names the body radius that fits: that is the fix
            raise
        raise ConfigError(f"{str(err).split('; ')[0]}; {stray}") from err
    field = wall.field
    if ingest.initial_surface is not None:
        field = _with_fitted_initial(chain, wall.settings, ingest.initial_surface[0], wall.field)
    summary = {**wall.summary(), "initial_radius": _initial_kind(case),
               "backbone": stretch_fit_errors(ingest.summary.get("backbone"), wall, curve),
               "end_cut": choose_end_cuts(fit.end_cut, ingest.summary.get("end_planes"),
                                          curve.frames(np.array([0.0, 1.0])), chain.shape.keys[-1].length,
                                          mould=case.export.mould is not None,
                                          parting_local=_parting_local(chain) if case.export.mould else None)}
    # the fitted body itself at every q of the morph's search, not only at q = 1 (issue 29)
    # its reports around the export q's curves (kinematics built them) are kept for the feasibility's per-q figures
    if field is wall.field and wall.field_results:
        reports = [_raised(r) for r in wall.field_results]
        morph = fold_over_morph_from(chain.shape.curve_at, field, q_grid, reports, built=chain.shape.built_curve)
    else:
        morph = fold_over_morph(chain.shape.curve_at, field, q_grid, map_items, built=chain.shape.built_curve)
    summary["morph_fold"] = morph.as_dict()
    warning = morph.warning(chain.shape.mode)
    if warning is not None:
        summary["warnings"] = [*summary.get("warnings", []), warning]
    if chain.shape.mode == "pcc":
        summary["pcc"] = _carried_to_chain(chain, curve)
    # the end prior can hold the ends a straying centerline leaves one-sided: the fit then succeeds, so say it
    stray = centerline_stray(case, curve.curve, path)
    if stray is not None:
        summary["centerline_stray"] = stray.replace("the cause is the centerline, not the fit: ", "the centerline, ")
    # the fit measured it against its own field (beside the hold-out); a fitted initial surface is a new field
    residual = wall.residual if field is wall.field else wall.polar.rho - fitted_rho(field, wall.polar.l,
                                                                                 wall.polar.angle)
    points = {
        "l": wall.polar.l,
        "angle": wall.polar.angle,
        "rho": wall.polar.rho,
        "residual": residual,
        "reason": wall.selection.reason,
        "distance": wall.distance,
    }
    return FitResult(field, summary, points)


def _morph_job(chain: LinkChain, field: RadiusField, q_grid: FloatArray) -> tuple[Callable[[float], Any], list[float]]:
    """The fitted body's morph grid (:func:`~softdesign.fitting.morph_folds.morph_grid`) as work the wall fit runs
    in its hold-out's pool: a q whose check raises returns the error instead, raised by :func:`_raised` where the
    morph is checked, after the fit's own checks (the same error, in the same place, as a pool of its own)."""
    task, items = morph_grid(chain.shape.curve_at, field, q_grid)

    def kept(q: float) -> Any:
        try:
            return task(q)
        except Exception as err:  # noqa: BLE001 - raised again, unchanged, by _raised
            return err

    return kept, items


def _raised(result: Any) -> Any:
    """``result``, or raised when it is an error :func:`_morph_job` kept."""
    if isinstance(result, Exception):
        raise result
    return result


def fitted_rho(field: RadiusField, l: FloatArray, angle: FloatArray) -> FloatArray:
    """rho(1, l, angle) of ``field`` at every point (n,), mm: ``PROJECT_BLOCK`` points a task on the build's workers.

    Each point's value is its own (its link's spline at its l and angle), so the blocks give the numbers of one
    ``evaluate_pairs`` call over all the points; a surface's worth of points (1M vertices) no longer waits on
    this process alone.
    """
    return mapped_blocks(lambda rows: field.evaluate_pairs(1.0, l[rows], angle[rows]), len(l), PROJECT_BLOCK,
                         map_items)


def _carried_to_chain(chain: LinkChain, vessel: Any) -> dict[str, Any]:
    """blend: pcc: how far the wall, fitted around the vessel's centerline, is carried to reach the chain at q = 1."""
    l = chain.shape.keys[-1].dense_l()
    moved = np.linalg.norm(chain.shape.smooth_curve_at(1.0).points(l) - vessel.points(l), axis=1)
    worst = int(np.argmax(moved))
    return {
        "max_axis_shift_mm": float(moved[worst]),
        "at_l": float(l[worst]),
        "note": "the wall is fitted around the vessel's centerline and carried onto the designed chain by arc-length "
                "fraction per section: at q = 1 each ring of the body sits on the chain's point at the same l, up to "
                "max_axis_shift_mm from the vessel's (the chain's true distance to the centerline, "
                "design/summary.json: chain_max_deviation_mm, is at most this)",
    }


def centerline_stray(case: Case, curve: SmoothCurve, path: SelectedPath) -> str | None:
    """Why a fit failed when the resampled, smoothed centerline strays from the input one; None when it does not.

    The wall is measured as distances from the centerline: a centerline that
    has left the vessel's axis by a good part of the radius (too much
    ``resample.smoothing_mm``, or too coarse a ``resample.spacing_mm``) gives
    radii that no fit smoothing can repair, so the message names those keys
    rather than ``fit.smoothing``.
    """
    deviation = measure_deviation(curve, path.points)
    radius = float(np.min(path.radius)) if path.radius is not None else None
    worst = int(np.argmax(deviation))
    if radius is None or deviation[worst] < STRAY_FRACTION * radius:
        return None
    r = case.resample
    return (
        f"the cause is the centerline, not the fit: resampled every {r.spacing_mm:g} mm (resample.spacing_mm) and "
        f"smoothed by {r.smoothing_mm:g} mm (resample.smoothing_mm), it strays {deviation[worst]:.2f} mm from the "
        f"input centerline near input point {worst}, {deviation[worst] / radius:.0%} of the vessel's smallest "
        f"radius ({radius:.2f} mm; at most {STRAY_FRACTION:.0%} keeps the wall measurable): lower "
        "resample.smoothing_mm (or resample.spacing_mm)"
    )


def _with_fitted_initial(chain, settings: FitSettings, vertices: np.ndarray, final: RadiusField) -> RadiusField:
    """rho0 from ``initial.surface``: projected on the q = 0 centerline and fitted with the final's layout."""
    initial_curve = chain.shape.curve_at(0.0)
    polar = project_points(initial_curve, vertices)
    inside = polar.subset(polar.end_side == 0)
    initial = fit_radius_surface(inside, chain.shape.keys[-1].length, settings)
    return RadiusField(final.breaks, final.final, initial.links)


def _initial_kind(case: Case) -> str:
    if case.initial.radius_mm is not None:
        return f"constant {case.initial.radius_mm:g} mm"
    return "fitted initial.surface" if case.initial.surface is not None else "axially symmetric mean of the fit"


def write_fit(result: FitResult, staging: Staging) -> None:
    """Keep the radius field, the points and the figures."""
    staging.write_bytes(layout.FIT_SURFACE, npz_bytes(**result.field.to_arrays()))
    staging.write_bytes(layout.FIT_POINTS, npz_bytes(**result.points))
    staging.write_json(layout.FIT_SUMMARY, result.summary)


def load_fit(build_dir: Path) -> FitResult:
    """The kept radius field and figures."""
    root = Path(build_dir)
    field = RadiusField.from_arrays(load_npz(root / layout.FIT_SURFACE))
    summary = json.loads((root / layout.FIT_SUMMARY).read_text(encoding="utf-8"))
    return FitResult(field, summary, load_npz(root / layout.FIT_POINTS))


def fit_metrics(result: FitResult) -> dict[str, Any]:
    """The manifest's fit block: true distances (mm), hold-out, counts, joints, rho * kappa."""
    s = result.summary
    d = s["distance"]
    return {
        "rms_mm": d["rms_mm"],
        "p95_mm": d["p95_mm"],
        "p99_mm": d["p99_mm"],
        "max_mm": d["max_mm"],
        "holdout_rms_mm": s["holdout_rms_mm"],
        "holdout_points": s["holdout_points"],
        "points": s["points"],
        "settings": s["settings"],
        "joint_value_jump_mm": max(s["joint_value_jump_mm"], default=0.0),
        "joint_slope_jump": max(s["joint_slope_jump"], default=0.0),
        "max_rho_kappa": s["max_rho_kappa"],
        "backbone": s.get("backbone", []),
        "ends": s.get("ends", {}),
        "end_prior": s.get("end_prior", {}),
        "end_cut": s.get("end_cut", {}),
        # rms_mm .. max_mm above are on the kept points; the same under ``kept``, and on all of the path's own
        # wall under ``all_wall``, with the ``coverage`` and the ``flags`` the report names (issue 29)
        "kept": {k: d[k] for k in ("rms_mm", "p95_mm", "p99_mm", "max_mm", "count")},
        **{k: s[k] for k in ("all_wall", "all_wall_outside_local_caps", "coverage", "flags", "warnings", "morph_fold")
           if k in s},
    }


def describe_fit(result: FitResult) -> list[str]:
    """The metrics table."""
    m = fit_metrics(result)
    p = m["points"]
    st = m["settings"]
    return [
        f"points: {p['input']} input, {p['kept']} kept; dropped: other branch {p['other_branch']}, "
        f"cap {p['cap']}, outlier {p['outlier']}",
        f"spline: knots every {st['knot_spacing_mm']:g} mm, {st['angular_intervals']} angular intervals, "
        f"smoothing {st['smoothing']:g}",
        f"true distance to the fitted surface, kept points (mm){_sampled_note(result.summary['distance'])}:",
        f"  kept-point RMS {m['rms_mm']:.4f}  p95 {m['p95_mm']:.4f}  p99 {m['p99_mm']:.4f}  max {m['max_mm']:.4f}",
        f"  hold-out RMS {m['holdout_rms_mm']:.4f} (k-fold on {result.summary['holdout_points']} kept points: each "
        "fold measured against the fit made without it)",
        *coverage_lines(result.summary),
        f"joints: value jump {m['joint_value_jump_mm']:.2e} mm, slope jump {m['joint_slope_jump']:.2e}",
        f"max rho * kappa at q = 1: {m['max_rho_kappa']:.3f} (folds at 1; every export q is checked at export)",
        *_morph_lines(result.summary),
        f"radius at q = 0: {result.summary['initial_radius']}",
    ] + end_lines(result.summary) + describe_backbone_fit(result.summary.get("backbone", []))


def coverage_lines(summary: dict[str, Any]) -> list[str]:
    """The all-wall figures, the coverage and each unseen stretch (none for older builds); the warnings are
    :func:`~softdesign.pipeline.stages.fit_notices.fit_notices`'s."""
    if "all_wall" not in summary:
        return []
    a, c = summary["all_wall"], summary["coverage"]
    lines = [
        f"true distance, all of the path's own wall ({c['own_wall_points']} vertices, {c['fraction']:.1%} of them "
        f"fitted):",
        f"  all-wall RMS {a['rms_mm']:.4f}  p95 {a['p95_mm']:.4f}  p99 {a['p99_mm']:.4f}  max {a['max_mm']:.4f}",
    ]
    if "all_wall_outside_local_caps" in summary:  # fit.local_max_radius holds the body thinner there on purpose
        o = summary["all_wall_outside_local_caps"]
        spans = ", ".join(f"{lo:.1f}-{hi:.1f}" for lo, hi in o["spans_mm"])
        lines.append(f"  outside the capped stretches ({spans} mm): RMS {o['rms_mm']:.4f}  p95 {o['p95_mm']:.4f}  "
                     f"p99 {o['p99_mm']:.4f}  max {o['max_mm']:.4f} ({o['count']} vertices)")
    lines += [f"  wall not seen all round at {s['from_mm']:.1f}-{s['to_mm']:.1f} mm ({s['length_mm']:.1f} mm, local "
              f"diameter {s['diameter_mm']:.1f} mm): {s['how']}" for s in c["unseen_stretches"]]
    return lines


def _morph_lines(summary: dict[str, Any]) -> list[str]:
    m = summary.get("morph_fold")
    if m is None:
        return []
    return [f"max rho * kappa over the morph ({m['q_samples']} q, refined): {m['max_rho_kappa']:.3f} at q = "
            f"{m['q']:.3f}, l = {m['l']:.4f}"]


def end_lines(summary: dict[str, Any]) -> list[str]:
    """Where an end's wall was unseen and held at the inscribed radius, and how each end was cut (its warnings are
    :func:`~softdesign.pipeline.stages.fit_notices.fit_notices`'s)."""
    lines = [
        f"{end}: wall not seen all round over the last {e['unseen_mm']:.1f} mm; {e['empty_cells']:.0f} empty cells "
        f"held at the inscribed radius ({e['reference_min_mm']:.3f} to {e['reference_max_mm']:.3f} mm)"
        for end, e in summary.get("end_prior", {}).items()
    ]
    cuts = summary.get("end_cut", {})
    lines += [f"{end}: cut at the detected plane (tilt {c['tilt_deg']:.1f} deg, rim gap {c['rim_gap_mm']:.3f} mm)"
              if c["applied"] else f"{end}: cut square to the end tangent ({c['reason']})" for end, c in cuts.items()]
    return lines


def _sampled_note(distance: dict[str, Any]) -> str:
    """How many points the distance figures saw, when not every kept point (large inputs)."""
    total = distance.get("total", distance["count"])
    if distance["count"] == total:
        return ""
    return f", RMS and percentiles over a seeded sample of {distance['count']:,} of {total:,} points, max over all"


STAGE = Stage(
    name="fit",
    version=VERSION,
    reads=("fit", "initial.radius_mm", "initial.surface", "export.mould"),  # a mould turns auto's cuts
    upstream=("ingest", "links"),
    compute=lambda case, results: run_fit(case, results["ingest"], results["links"]),
    write=write_fit,
    load=lambda build_dir, results: load_fit(build_dir),
    describe=describe_fit,
    metrics=fit_metrics,
    warnings=lambda result: fit_notices(result.summary),
)
