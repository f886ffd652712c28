"""``blend: auto`` judged on the fitted body: the wall fitted before the blend is chosen, and its morph's folds.

The reach ``r * kappa`` of the inscribed radius (:mod:`softdesign.geometry.morph_fold`)
sees a morph fold coming from the centerlines alone, but the wall is wider
than its inscribed sphere on an elliptical or flared section: a carotid and
a cerebral path that pass it were refused at export with ``rho * kappa`` of
4.08 and 1.16 at q = 0.5.  ``auto`` therefore also fits the wall (the fit
stage's projection, selection, end prior, caps and links, on at most
``BODY_POINTS`` of the surface's vertices, an even stride through them) and
measures ``rho(q) * kappa_n(q)`` over the morph as the fit stage does
(:func:`softdesign.fitting.morph_folds.fold_over_morph`).  Where the linear
blend's body reaches ``BODY_FOLD_LIMIT`` before q = 1, ``auto`` builds the
intrinsic blend when its body folds less.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from softdesign.errors import FitError
from softdesign.fitting.morph_folds import MorphFold, fold_over_morph_from, morph_grid
from softdesign.fitting.projection import PolarPoints, project_points
from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.selection import NetworkContext, inscribed_profile
from softdesign.fitting.wall_fit import fit_body
from softdesign.geometry.blend import BlendedShape
from softdesign.geometry.morph_fold import morph_q_grid
from softdesign.kinematics.links import link_breaks
from softdesign.pipeline.fit_options import AUTO_START_SPACING_MM, wall_fit_options
from softdesign.pipeline.item_progress import step_counter
from softdesign.pipeline.parallel import map_items

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.pipeline.stages.ingest import IngestResult

#: The most surface vertices the look at the body fits (an even stride through them above it): the body's
#: folds are a matter of its radius over a knot interval, which a tenth of a 1M-vertex wall still sees.
BODY_POINTS = 100_000
#: The name under which the body's projection of the wall is kept on the shape (:func:`known_projection`).
WALL_PROJECTION = "wall_projection"
#: The body's rho * kappa_n at which a morph folds (the export's, :data:`softdesign.meshing.tessellate.FOLD_LIMIT`).
BODY_FOLD_LIMIT = 1.0


def body_field(case: Case, ingest: IngestResult, shape: BlendedShape) -> RadiusField | None:
    """The wall fitted around the q = 1 centerline of ``shape`` as the fit stage fits it; None without a surface
    or when the quick fit fails (the fit stage then says why)."""
    if len(ingest.faces) == 0:
        return None
    curve = shape.target_curve()
    path = ingest.path
    inscribed = (None, None) if path.radius is None else inscribed_profile(curve, path.points, path.radius)
    network = NetworkContext(path.points, tuple(p.points for p in ingest.others), *inscribed)
    rule = case.links
    breaks = link_breaks(shape.keys[-1].length, rule.count, rule.breaks, rule.length_mm)
    options = wall_fit_options(case, tuple(float(b) for b in breaks), map_items)  # the projection on the workers
    if case.fit.knot_spacing_mm == "auto":  # no hold-out here: the spacing auto starts from
        options = replace(options, fit=replace(options.fit, knot_spacing_mm=AUTO_START_SPACING_MM))
    vertices = np.asarray(ingest.vertices, float)
    rows = slice(None, None, max(1, -(-len(vertices) // BODY_POINTS)))
    step = step_counter("blend", ("the wall fitted for auto's look at the body",))  # seconds on a big tree
    try:
        polar = project_points(curve, vertices[rows], map_items)
        # the fit stage fits around this very curve when the stage keeps this shape: it takes these rows from here
        shape.keep(WALL_PROJECTION, (ingest.vertices, curve, rows, polar))
        return fit_body(curve, vertices[rows], network, options, polar)
    except FitError:
        return None
    finally:
        step("the wall fitted for auto's look at the body")


def known_projection(shape: BlendedShape, vertices: object, curve: object) -> tuple[slice, PolarPoints] | None:
    """The rows of ``vertices`` the look at the body projected on ``curve``, and their projection, taken from
    ``shape`` (:func:`body_field` kept them); None unless they were of these very vertices and this very curve."""
    kept = shape.take(WALL_PROJECTION)
    if not isinstance(kept, tuple) or kept[0] is not vertices or kept[1] is not curve:
        return None
    return kept[2], kept[3]


def body_morph(shape: BlendedShape, field: RadiusField) -> MorphFold:
    """The largest rho(q) * kappa_n(q) of the body over ``shape``'s morph (the fit stage's q grid).

    Each q's curve and fold margin are their own, on the build's workers (on free cores they halve the stage's
    largest step); the curves come back with the reports and are kept on ``shape``
    (:meth:`~softdesign.geometry.blend.BlendedShape.keep_curve`), so that a stage that builds on this very shape
    (the blend stage keeps the one it judged, :func:`softdesign.pipeline.blend_choice.choose_blend`) finds them
    built: the kinematics' export q are this grid's.  The same reports as
    :func:`~softdesign.fitting.morph_folds.fold_over_morph`.
    """
    q_grid = morph_q_grid()
    task, items = morph_grid(shape.curve_at, field, q_grid)
    done = map_items(lambda q: (task(q), shape.curve_at(float(q))), items)
    for q, (_, curve) in zip(items, done, strict=True):
        shape.keep_curve(q, curve)
    return fold_over_morph_from(shape.curve_at, field, q_grid, [report for report, _ in done])


def body_folds(fold: MorphFold) -> bool:
    """The body folds before q = 1 (q = 1 itself is the fit's to refuse, whatever the blend)."""
    return fold.q < 1.0 and fold.report.max_rho_kappa >= BODY_FOLD_LIMIT
