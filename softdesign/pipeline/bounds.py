"""The sizes that follow from a spacing and the vessel's length, checked once ingest has measured the vessel.

``resample.spacing_mm: 1e-6`` is a valid number but asks for 10^8 samples
along a 100 mm artery; ``export.spacing_mm`` and ``export.angular_count``
together fix the vertices of every mesh.  These counts depend on the length
of the shapes, which only ingest knows, so the runner calls
:func:`check_sizes` right after ingest and before any other stage starts.
Each bound is a constant of :mod:`softdesign.limits`, where the memory
budget they keep a build within is derived.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from softdesign.errors import ConfigError
from softdesign.limits import (
    MAX_CURVE_SAMPLES,
    MAX_EXPORT_VERTICES,
    MAX_FIT_COEFFICIENTS,
    MAX_LINKS,
    MAX_MESH_VERTICES,
    MEMORY_BUDGET_TEXT,
)
from softdesign.pipeline.offset_bound import check_offset

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

if TYPE_CHECKING:  # the export and feasibility stages import this module: no import of the stages here
    from softdesign.pipeline.stages.ingest import IngestResult

#: A length ratio counts as a whole number of intervals within this (for the "at least" spacing in messages).
_GRACE = 1.0 + 1e-9
#: fit.end_margin_mm is at most this share of the final path's length (both margins leave half of it).
END_MARGIN_SHARE = 0.25


def longest_shape_mm(case: Case, ingest: IngestResult) -> float:
    """The longest key shape, mm: the final path, the q = 0 shape and every keyframe.

    Every shape of the blend is at most as long as the longest key shape
    (a linear blend of curves is no longer than the longer of the two), so
    this bounds the rings of every export mesh.
    """
    lengths = [ingest.path.length]
    lengths += [p.length for _, p in ingest.keyframes]
    if ingest.initial_path is not None:
        lengths.append(ingest.initial_path.length)
    if case.initial.length_mm is not None:
        lengths.append(case.initial.length_mm)
    return max(lengths)


def check_sizes(case: Case, ingest: IngestResult) -> None:
    """Refuse a case whose spacings ask for more than the limits on this vessel (ConfigError: key, value, limit, fix).

    Parameters
    ----------
    case : the validated case
    ingest : the measured inputs (the final path's length, mm, sets the samples, links and knots)
    """
    final = ingest.path.length
    longest = longest_shape_mm(case, ingest)
    r = case.resample
    if r.count is None:
        _at_most("resample.spacing_mm", r.spacing_mm, "samples along", final, MAX_CURVE_SAMPLES, "centerline samples")
    if case.links.length_mm is not None:
        _at_most("links.length_mm", case.links.length_mm, "links along", final, MAX_LINKS, "links")
    if case.fit.knot_spacing_mm != "auto":
        spacing = float(case.fit.knot_spacing_mm)
        intervals = max(1, round(final / spacing))
        coefficients = (intervals + 3) * case.fit.angular_intervals
        if coefficients > MAX_FIT_COEFFICIENTS:
            least = final / (MAX_FIT_COEFFICIENTS // case.fit.angular_intervals - 3)
            raise ConfigError(
                f"fit.knot_spacing_mm: {spacing:g} mm with fit.angular_intervals {case.fit.angular_intervals} gives "
                f"{coefficients} spline coefficients on the {final:.1f} mm final path, more than the limit of "
                f"{MAX_FIT_COEFFICIENTS} ({_BUDGET}); use fit.knot_spacing_mm >= {_up(least)} mm "
                "or fewer fit.angular_intervals"
            )
    if case.fit.end_margin_mm > END_MARGIN_SHARE * final:
        raise ConfigError(
            f"fit.end_margin_mm: {case.fit.end_margin_mm:g} mm is more than {END_MARGIN_SHARE:g} of the "
            f"{final:.1f} mm final path (the margins at both ends would leave too little wall to fit); "
            f"use fit.end_margin_mm <= {END_MARGIN_SHARE * final:.3g}"
        )
    _check_meshes(case, longest)
    check_offset(case, ingest)  # before the fit: an offset the vessel's radius cannot take


_BUDGET = f"softdesign/limits/__init__.py, which keeps a build within {MEMORY_BUDGET_TEXT} of memory"


def _up(value: float) -> str:
    """``value`` rounded up to 3 significant digits, for an 'at least' in a message."""
    if value <= 0:
        return "0"
    step = 10 ** (math.floor(math.log10(value)) - 2)
    return f"{math.ceil(value / step) * step:.6g}"


def _at_most(key: str, spacing: float, what: str, length: float, limit: int, name: str) -> None:
    count = length / spacing
    if count > limit * _GRACE:
        raise ConfigError(
            f"{key}: {spacing:g} mm gives {count:.4g} {name} along the {length:.1f} mm final path, more than the "
            f"limit of {limit} ({_BUDGET}); use {key} >= {_up(length / limit)} mm"
        )


def mesh_vertices(case: Case, longest: float) -> int:
    """About how many vertices each export mesh has on a shape ``longest`` mm long (rings x around, x 2 hollow)."""
    e = case.export
    walls = 1 if e.wall_mm is None else 2  # a hollow body has the chamber's rings too
    return (math.ceil(longest / e.spacing_mm) + 1) * e.angular_count * walls


def meshes_at_once(case: Case, longest: float) -> int:
    """How many export meshes may be built at the same time (by parallel workers) within the memory budget.

    The budget holds one mesh of MAX_MESH_VERTICES while it is built (softdesign/limits/__init__.py); as many
    meshes as together have that many vertices fit in the same memory, each in its own worker.
    """
    return max(1, MAX_MESH_VERTICES // max(1, mesh_vertices(case, longest)))


#: Mesh vertices worth one export worker: a pool of forked workers takes about 0.25 s to start (measured with a
#: 400 MB build process on the 2-core benchmark machine), about what building, checking and keeping 50,000
#: vertices of mesh takes there (the benchmark case: 28,600 vertices a mesh, 0.15 to 0.25 s each).
VERTICES_PER_WORKER = 50_000


def export_workers(case: Case, longest: float) -> int:
    """The most worker processes the export stage uses: as many meshes as fit in memory, and worth starting."""
    total = mesh_vertices(case, longest) * len(case.export.q_values())
    return max(1, min(meshes_at_once(case, longest), total // VERTICES_PER_WORKER))


def _check_meshes(case: Case, longest: float) -> None:
    e = case.export
    walls = 1 if e.wall_mm is None else 2  # a hollow body has the chamber's rings too
    per_mesh = mesh_vertices(case, longest)
    if per_mesh > MAX_MESH_VERTICES:
        least = longest / (MAX_MESH_VERTICES / (e.angular_count * walls) - 1)
        raise ConfigError(
            f"export.spacing_mm: {e.spacing_mm:g} mm with export.angular_count {e.angular_count} gives about "
            f"{per_mesh} vertices per mesh on the {longest:.1f} mm shape, more than the limit of {MAX_MESH_VERTICES} "
            f"({_BUDGET}); use export.spacing_mm >= {_up(least)} mm or a smaller export.angular_count"
        )
    count = len(e.q_values())
    if per_mesh * count > MAX_EXPORT_VERTICES:
        most = max(1, MAX_EXPORT_VERTICES // per_mesh)
        key = "export.frames" if e.frames is not None else "export.q"
        raise ConfigError(
            f"{key}: {count} meshes of about {per_mesh} vertices each make {per_mesh * count} vertices, more than "
            f"the limit of {MAX_EXPORT_VERTICES} for all meshes together ({_BUDGET}); export at most {most} q values "
            "at this resolution, or raise export.spacing_mm"
        )
