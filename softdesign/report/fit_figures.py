"""Figure 3, fit quality: signed residual maps per link, true distances, and the points left out.

The residual map shows, per link, the mean signed radial residual
rho_point - rho_fit(l, a) (mm) of the kept wall points in bins of about one
knot spacing along the centerline by one angular knot interval around it.
The histogram shows the true point-to-surface distances of the kept points
the fit measured (closest point on the fitted surface at q = 1, from each
point's projection; kept in ``fit/points.npz``, or measured here the same way
for an older build folder); the manifest's RMS, p95, p99 and max are drawn on
it.  The map beside it shows every surface vertex by the reason it was kept or
left out; a large surface's map draws only the vertex left on top in each
half-pixel cell.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.errors import InputDataError
from softdesign.fitting.closest import closest_surface_points
from softdesign.fitting.projection import PolarPoints
from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.selection import REASONS
from softdesign.pipeline.stages.fit import FitResult
from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture, fixed_figure, grid_shape, panels, picture, styled
from softdesign.report.projection import painted_last
from softdesign.report.surface_figures import final_view
from softdesign.types import FloatArray

RESIDUAL_SIZE_IN = (12.0, 6.0)
DISTANCE_SIZE_IN = (12.0, 4.2)
#: Fixed layout of the distance figure's three panels, inches: margins (left, right, bottom, top) and the gap
#: between panels, room for tick labels up to 6 characters wide, the axis labels and one line of title.
DISTANCE_MARGINS_IN, DISTANCE_GAP_IN = (0.7, 0.2, 0.5, 0.35), 0.8
#: The same for the residual maps (two per row); the right margin holds the colour bar's ticks and label.
RESIDUAL_MARGINS_IN, RESIDUAL_GAPS_IN = (0.75, 1.0, 0.45, 0.3), (0.8, 0.7)
#: Percentile of |bin mean| setting the residual maps' colour scale (one wild bin must not wash out the rest).
RESIDUAL_SCALE_PERCENTILE = 99.0
#: Background of residual bins that hold no kept point.
EMPTY_BIN_COLOUR = "#b0b0b0"
#: Histogram bins of the true distances.
DISTANCE_BINS = 60
#: Colours of the point classes: kept, then each exclusion reason in ``REASONS`` order.
REASON_COLOURS = ("#c7c7c7", "#ff7f0e", "#9467bd", "#d62728")
#: Surface vertices above which the exclusion map draws only the one left on top in each half-pixel cell (the
#: picture differs by under a pixel; 500,000 markers took a large vessel's report 1.5 s to draw).
MAP_POINTS = 50_000
#: The map's cell, in pixels of its axes.
MAP_CELL_PX = 0.5
#: The manifest's distance figures drawn on the histogram, with their line styles.
DISTANCE_MARKS = (("rms_mm", "RMS", "-"), ("p95_mm", "p95", "--"), ("p99_mm", "p99", "-."), ("max_mm", "max", ":"))


class _FieldAtQ:
    """rho(q) of a radius field behind the one-spline interface the distance measurement expects."""

    def __init__(self, field: RadiusField, q: float) -> None:
        self.splines = [field.link_spline(j, q) for j in range(len(field.final))]
        self.field = field

    def evaluate(self, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        l, a = (np.asarray(v, float).reshape(-1) for v in (l, a))
        out = np.empty(len(l))
        owner = self.field.link_of(l)
        for j in np.unique(owner):
            rows = owner == j
            out[rows] = self.splines[int(j)].evaluate(l[rows], a[rows], dl, da)
        return out


def _fit_of(data: BuildData) -> FitResult:
    """The build's fit: the fit figures are drawn only for a build that has one (the writer checks)."""
    if data.fit is None:
        raise InputDataError(f"{data.build_dir}: the build has no fit to draw; run the fit stage first")
    return data.fit


def true_distances(data: BuildData) -> FloatArray:
    """True distances (m,) mm to the fitted surface at q = 1 of the kept wall points the fit's metrics measured.

    The fit keeps them (``fit/points.npz``, ``distance``: every kept point, or a seeded sample of a large input, as
    RMS, p95 and p99 are measured); a build folder from before it did has them measured here, for every kept point.
    """
    fit = _fit_of(data)
    points = fit.points
    if "distance" in points:
        measured = np.asarray(points["distance"], float)
        return measured[np.isfinite(measured)]
    keep = points["reason"] == 0
    polar = PolarPoints(
        data.ingest.vertices[keep], points["l"][keep], points["angle"][keep], points["rho"][keep],
        np.zeros(int(keep.sum()), np.int8),
    )
    curve = data.kinematics.chain.shape.target_curve()  # the wall is fitted around it (blend: pcc: the vessel's)
    return closest_surface_points(curve, _FieldAtQ(fit.field, 1.0), polar)[0]


def residual_bins(l_mm: FloatArray, angle: FloatArray, residual: FloatArray, edges: tuple[FloatArray, FloatArray]):
    """Mean residual (nx, ny) per (l mm, angle deg) bin; NaN where a bin holds no point."""
    total, _, _ = np.histogram2d(l_mm, np.degrees(angle), bins=edges, weights=residual)
    count, _, _ = np.histogram2d(l_mm, np.degrees(angle), bins=edges)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _link_maps(data: BuildData) -> list[tuple[FloatArray, FloatArray, FloatArray]]:
    """Per link: l edges (mm), angle edges (deg), mean residual per bin."""
    fit = _fit_of(data)
    p, breaks = fit.points, fit.field.breaks
    length = data.kinematics.chain.shape.keys[-1].length
    settings = fit.summary["settings"]
    keep = p["reason"] == 0
    l_mm, angle, residual = p["l"][keep] * length, p["angle"][keep], p["residual"][keep]
    angle_edges = np.linspace(-180.0, 180.0, int(settings["angular_intervals"]) + 1)
    out = []
    for j in range(len(breaks) - 1):
        lo, hi = breaks[j] * length, breaks[j + 1] * length
        count = max(int(round((hi - lo) / float(settings["knot_spacing_mm"]))), 4)
        edges = np.linspace(lo, hi, count + 1)
        inside = (l_mm >= lo) & (l_mm <= hi)
        mean = residual_bins(l_mm[inside], angle[inside], residual[inside], (edges, angle_edges))
        out.append((edges, angle_edges, mean))
    return out


def residual_picture(data: BuildData) -> Picture:
    """The signed residual maps, one panel per link, on one symmetric colour scale."""
    maps = _link_maps(data)
    values = np.concatenate([np.abs(m[2][np.isfinite(m[2])]) for m in maps] + [np.zeros(1)])
    scale = max(float(np.percentile(values, RESIDUAL_SCALE_PERCENTILE)), 1e-6)
    with styled():
        figure = fixed_figure(RESIDUAL_SIZE_IN, RESIDUAL_MARGINS_IN, RESIDUAL_GAPS_IN, grid_shape(len(maps), 2))
        mesh = None
        for j, ax in enumerate(panels(figure, len(maps), max_columns=2)):
            l_edges, a_edges, mean = maps[j]
            mesh = ax.pcolormesh(l_edges, a_edges, mean.T, cmap="RdBu_r", vmin=-scale, vmax=scale)
            ax.set_facecolor(EMPTY_BIN_COLOUR)  # bins without a kept point
            ax.set_title(f"link {j}")
            ax.set_xlabel("arc length from the inlet (mm)")
            ax.set_ylabel("angle from N towards B (deg)")
            ax.set_yticks([-180, -90, 0, 90, 180])
        figure.colorbar(mesh, ax=figure.axes, extend="both", label="mean signed residual rho - rho_fit (mm)")
    caption = (
        "Mean signed radial residual of the kept wall points (positive: the wall lies outside the fitted surface), "
        "per link, in bins of about one knot spacing by one angular interval; grey bins hold no kept point "
        f"(other branches, caps). Colour scale: +/- the {RESIDUAL_SCALE_PERCENTILE:g}th percentile of |bin mean| "
        f"= {scale:.3g} mm."
    )
    return picture("fit_residuals.png", figure, RESIDUAL_SIZE_IN, "Fit residual over (l, angle), per link", caption)


def distance_histogram(ax, distances: FloatArray, metrics: dict) -> None:
    """Histogram of true distances (log count) with the manifest's RMS, p95, p99 and max."""
    ax.hist(distances, bins=DISTANCE_BINS, color="#4c72b0", log=True)
    for key, label, style in DISTANCE_MARKS:
        if key in metrics:
            ax.axvline(metrics[key], color="k", ls=style, lw=1.0, label=f"{label} {metrics[key]:.4f} mm")
    ax.set_xlabel("true distance to the fitted surface (mm)")
    ax.set_ylabel("kept points")
    kept = metrics.get("points", {}).get("kept") if isinstance(metrics.get("points"), dict) else None
    sampled = isinstance(kept, int) and len(distances) < kept
    ax.set_title(f"{len(distances)} of {kept} kept points measured" if sampled else f"{len(distances)} kept points")
    ax.legend(loc="upper right")


def exclusion_views(ax_map, ax_bar, data: BuildData) -> int:
    """The surface's points coloured by why they were kept or left out, and their counts; the points drawn.

    Above :data:`MAP_POINTS` vertices the map draws, of the points in each :data:`MAP_CELL_PX` cell of its
    axes, the one a painter leaves on top (:func:`painted_last`).
    """
    from matplotlib.colors import to_rgba_array

    reason = _fit_of(data).points["reason"]
    view = final_view(data.kinematics.chain)
    order = np.argsort(view.coordinates(data.ingest.vertices)[:, 2], kind="stable")
    xy = view.project(data.ingest.vertices)[order]
    colours = to_rgba_array(REASON_COLOURS)[reason[order]]
    if len(xy) > MAP_POINTS:
        # data per pixel is at least the points' extent over the axes' pixels (margins and the equal aspect
        # only widen the limits), so the cell is at most MAP_CELL_PX pixels
        box = ax_map.get_window_extent()
        extent = np.ptp(xy, axis=0)
        shown = painted_last(xy, MAP_CELL_PX * max(extent[0] / box.width, extent[1] / box.height, 1e-12))
        xy, colours = xy[shown], colours[shown]
    ax_map.scatter(xy[:, 0], xy[:, 1], s=1.0, c=colours, linewidths=0)
    ax_map.set_aspect("equal", adjustable="datalim")
    ax_map.set_xlabel(view.labels[0])
    ax_map.set_ylabel(view.labels[1])
    ax_map.set_title("surface points by reason")
    names = ("kept",) + REASONS
    counts = [int(np.sum(reason == k)) for k in range(len(names))]
    bars = ax_bar.bar(range(len(names)), counts, color=REASON_COLOURS[: len(names)])
    ax_bar.bar_label(bars, labels=[str(c) for c in counts], fontsize=7)
    ax_bar.set_xticks(range(len(names)), [n.replace("_", " ") for n in names])
    ax_bar.set_ylabel("surface points")
    ax_bar.set_title("kept and excluded points")
    return len(xy)


def distance_picture(data: BuildData, distances: FloatArray) -> Picture:
    """The distance histogram and the excluded points, side by side."""
    metrics = data.manifest.get("metrics", {}).get("fit", {})
    with styled():
        figure = fixed_figure(DISTANCE_SIZE_IN, DISTANCE_MARGINS_IN, (DISTANCE_GAP_IN, 0.0), (1, 3))
        grid = figure.add_gridspec(1, 3, width_ratios=(1.2, 1.4, 0.8))
        distance_histogram(figure.add_subplot(grid[0]), distances, metrics)
        shown = exclusion_views(figure.add_subplot(grid[1]), figure.add_subplot(grid[2]), data)
    caption = (
        "Left: true point-to-surface distances of the kept wall points the fit measured (every one but those "
        "within fit.end_margin_mm of an end, or a seeded sample of a large input), the points of the manifest's "
        "metrics.fit, drawn as lines. Middle and right: every surface vertex by the reason it was kept or left out "
        "of the fit (other branch, cap, outlier), seen as in the surface figure."
    )
    total = len(data.ingest.vertices)
    if shown < total:
        caption += (f" The map draws {shown} of the {total} vertices: of those within each {MAP_CELL_PX:g}-pixel "
                    "square, the one drawn last (nearest the viewer), so the picture differs by under a pixel.")
    return picture("fit_distances.png", figure, DISTANCE_SIZE_IN, "Fit distances and excluded points", caption)
