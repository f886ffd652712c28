"""Figure 4, kinematics over q: per link POE theta1, theta2, length, stretch, curvature; PCC chambers.

The series are computed here at :data:`Q_SAMPLES` evenly spaced q plus every
export q, on the link chain rebuilt from the build folder
(:meth:`LinkChain.reports`), every link at the same q.  The export q are
marked; there the values equal ``kinematics.json``'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.kinematics.links import LinkChain
from softdesign.report.plotting import Picture, fixed_figure, link_colours, new_figure, panels, picture, styled
from softdesign.types import FloatArray

SIZE_IN = (12.0, 7.0)
PCC_SIZE_IN = (12.0, 4.2)
#: Fixed layout of the 2 x 3 panels, inches: margins (left, right, bottom, top) and gaps (columns, rows),
#: room for tick labels up to 7 characters wide, the axis labels and one line of title.
MARGINS_IN, GAPS_IN = (0.75, 0.25, 0.45, 0.28), (0.85, 0.75)
#: Evenly spaced q of the series (0 and 1 included); the export q are added.
Q_SAMPLES = 41
#: Backbone samples per link of the PCC arc fit (pcc design's default is 201; the curves do not change visibly).
PCC_SAMPLES = 101
#: The three chambers: angle from N (deg, as seed 003's encoders) and line style.
CHAMBER_ANGLES_DEG = (90, 210, 330)
CHAMBER_STYLES = ("-", "--", ":")


@dataclass(frozen=True)
class KinematicsSeries:
    """Per q (m,) and link (n,): arrays of shape (m, n) in mm, rad, 1/mm; the chain's tip distance (m,) mm."""

    q: FloatArray
    export_q: FloatArray
    theta1: FloatArray
    theta2: FloatArray
    length: FloatArray
    stretch_min: FloatArray
    stretch_max: FloatArray
    curvature_max: FloatArray
    tip_distance: FloatArray


def q_grid(export_q: list[float], samples: int = Q_SAMPLES) -> FloatArray:
    """Evenly spaced q in [0, 1] merged with the export q, sorted, without duplicates."""
    return np.unique(np.concatenate([np.linspace(0.0, 1.0, samples), np.asarray(export_q, float)]))


def kinematics_series(chain: LinkChain, export_q: list[float], samples: int = Q_SAMPLES) -> KinematicsSeries:
    """Evaluate every link's report at each q of :func:`q_grid`."""
    q = q_grid(export_q, samples)
    names = ("theta1", "theta2", "length", "stretch_min", "stretch_max", "curvature_max")
    rows: dict[str, list[list[float]]] = {k: [] for k in names}
    tip = []
    for value in q:
        reports = chain.reports(float(value))
        rows["theta1"].append([r.poe.theta1 for r in reports])
        rows["theta2"].append([r.poe.theta2 for r in reports])
        rows["length"].append([r.length_mm for r in reports])
        rows["stretch_min"].append([r.stats.stretch_min for r in reports])
        rows["stretch_max"].append([r.stats.stretch_max for r in reports])
        rows["curvature_max"].append([r.stats.curvature_max_per_mm for r in reports])
        tip2base = np.linalg.multi_dot([np.eye(4)] + [r.transform for r in reports])
        tip.append(float(np.linalg.norm(tip2base[:3, 3])))
    arrays = {k: np.array(v, float) for k, v in rows.items()}
    return KinematicsSeries(q, np.asarray(export_q, float), tip_distance=np.array(tip), **arrays)


#: (attribute, title, y label) of the per-link panels.
PANELS = (
    ("theta1", "POE theta1 (translation)", "theta1 (mm)"),
    ("theta2", "POE theta2 (rotation)", "theta2 (rad)"),
    ("length", "link arc length", "length (mm)"),
    ("stretch", "axial stretch |dc/dl|(q) / |dc/dl|(0)", "stretch (min..max over the link)"),
    ("curvature_max", "largest curvature", "curvature (1/mm)"),
)


def _mark_export_q(ax, series: KinematicsSeries) -> None:
    for q in series.export_q:
        ax.axvline(q, color="#999999", lw=0.6, ls=":")


def kinematics_picture(series: KinematicsSeries) -> Picture:
    """Five per-link panels over q and the chain's base-to-tip distance."""
    colours = link_colours(series.theta1.shape[1])
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, GAPS_IN, (2, 3))
        for k, (name, title, label) in enumerate(PANELS):
            ax = figure.add_subplot(2, 3, k + 1)
            for j, colour in enumerate(colours):
                if name == "stretch":
                    ax.fill_between(series.q, series.stretch_min[:, j], series.stretch_max[:, j],
                                    color=colour, alpha=0.25)
                    ax.plot(series.q, series.stretch_min[:, j], color=colour, lw=1.2, label=f"link {j}")
                    ax.plot(series.q, series.stretch_max[:, j], color=colour, lw=1.2)
                else:
                    ax.plot(series.q, getattr(series, name)[:, j], color=colour, lw=1.4, label=f"link {j}")
            _mark_export_q(ax, series)
            ax.set(title=title, xlabel="q", ylabel=label, xlim=(0.0, 1.0))
        ax = figure.add_subplot(2, 3, 6)
        ax.plot(series.q, series.tip_distance, color="k", lw=1.4)
        _mark_export_q(ax, series)
        ax.set(title="base to tip distance", xlabel="q", ylabel="|translation of base_to_tip| (mm)", xlim=(0.0, 1.0))
        figure.axes[0].legend(loc="best")
    caption = (
        f"Every link at the same q, evaluated at {len(series.q)} values of q on the rebuilt link chain; "
        "dotted verticals mark the export q (values there equal kinematics.json). "
        "S_T_E = exp(xi1 theta1) exp(omega theta2): theta1 is the translation length, theta2 the rotation angle. "
        "Stretch is the speed of c(q, .) over that at q = 0 along the link (shaded between its min and max)."
    )
    return picture("kinematics.png", figure, SIZE_IN, "Kinematics over q, per link", caption)


def pcc_chamber_series(chain: LinkChain, q: FloatArray, d: float | list[float]):
    """Chamber lengths (m, n_links, 3) mm and the design's notes, from :func:`pcc_fit.design_sections`."""
    from softdesign.kinematics.pcc_fit import design_sections

    design = design_sections(chain, q, d, samples=PCC_SAMPLES)
    lengths = np.array([[link.chamber_lengths for link in pose.links] for pose in design.poses], float)
    deviation = np.array([[link.arc.backbone_max_mm for link in pose.links] for pose in design.poses], float)
    return lengths, deviation, design.d, list(design.notes)


def pcc_picture(chain: LinkChain, series: KinematicsSeries, d: float | list[float]) -> tuple[Picture, list[str]]:
    """Chamber lengths over q per link (one arc per link, seed 003) and how far each arc misses the design."""
    lengths, deviation, spacing, notes = pcc_chamber_series(chain, series.q, d)
    colours = link_colours(chain.count)
    with styled():
        figure = new_figure(PCC_SIZE_IN)
        axes = list(panels(figure, chain.count + 1, max_columns=5))
        for j, ax in enumerate(axes[:-1]):
            for k, (style, angle) in enumerate(zip(CHAMBER_STYLES, CHAMBER_ANGLES_DEG, strict=True)):
                ax.plot(series.q, lengths[:, j, k], color=colours[j], ls=style, lw=1.3, label=f"{angle} deg")
            _mark_export_q(ax, series)
            ax.set(title=f"link {j} chambers", xlabel="q", ylabel="chamber length (mm)", xlim=(0.0, 1.0))
            ax.legend(loc="best")
        for j, colour in enumerate(colours):
            axes[-1].plot(series.q, deviation[:, j], color=colour, lw=1.3, label=f"link {j}")
        _mark_export_q(axes[-1], series)
        axes[-1].set(title="arc vs design backbone", xlabel="q", ylabel="largest distance (mm)", xlim=(0.0, 1.0))
        axes[-1].legend(loc="best")
    d_text = ", ".join(f"{v:g}" for v in np.atleast_1d(spacing))
    caption = (
        f"One constant-curvature arc per link fitted to c(q, .) (softdesign pcc design), chambers d = {d_text} mm "
        "from the backbone at 90, 210, 330 degrees from N, one panel per link; last panel: the largest distance "
        "between each link's arc and the design's backbone."
    )
    return picture("pcc_chambers.png", figure, PCC_SIZE_IN, "PCC chamber lengths over q", caption), notes
