"""Figure 1, the morph: c(q, .) at every export q in three orthogonal views and one 3-D view.

Each link has its own colour; later q are drawn more opaque.  At every joint
(each link's start and end frame {S}, {E}) a small triad shows N, B, T in
red, green, blue.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.kinematics.links import LinkChain
from softdesign.report.plotting import TRIAD_COLOURS, Picture, fixed_figure, link_colours, picture, styled
from softdesign.report.projection import View, axis_views
from softdesign.types import FloatArray

SIZE_IN = (12.0, 9.0)
#: Fixed layout of the 2 x 2 views, inches: margins (left, right, bottom, top) and gaps (columns, rows); the
#: bottom margin holds the x labels and the legend's row under them.
MARGINS_IN, GAPS_IN = (0.75, 0.2, 0.75, 0.3), (0.85, 0.75)
#: Samples per link along each drawn centerline.
SAMPLES_PER_LINK = 60
#: Triad arm length as a fraction of the largest extent of all drawn centerlines.
TRIAD_FRACTION = 0.06
#: Opacity of the q = 0 curve; q = 1 is opaque.
FIRST_ALPHA = 0.35


@dataclass(frozen=True)
class MorphCurve:
    """One q: per-link points (n_links of (m, 3) mm) and the joint frames (n_links + 1, 4, 4)."""

    q: float
    links: tuple[FloatArray, ...]
    joints: FloatArray


def morph_curves(chain: LinkChain, q_values: list[float]) -> list[MorphCurve]:
    """Sample the centerline of every link and the joint poses F(q, l_j) at each q."""
    out = []
    for q in q_values:
        curve = chain.shape.curve_at(float(q))
        links = tuple(
            curve.points(np.linspace(chain.breaks[j], chain.breaks[j + 1], SAMPLES_PER_LINK))
            for j in range(chain.count)
        )
        out.append(MorphCurve(float(q), links, curve.poses(chain.breaks)))
    return out


def _alpha(q: float) -> float:
    return FIRST_ALPHA + (1.0 - FIRST_ALPHA) * float(np.clip(q, 0.0, 1.0))


def _extent(curves: list[MorphCurve]) -> float:
    points = np.concatenate([p for c in curves for p in c.links])
    return float(np.max(points.max(axis=0) - points.min(axis=0)))


def _triad_segments(poses: FloatArray, arm: float) -> list[FloatArray]:
    """Per axis k (N, B, T): segments (n_poses, 2, 3) from each pose's origin along its column k."""
    origins = poses[:, :3, 3]
    return [np.stack([origins, origins + arm * poses[:, :3, k]], axis=1) for k in range(3)]


def draw_view(ax, curves: list[MorphCurve], view: View, colours: list, arm: float) -> None:
    """One orthogonal view: every q's links, their triads and a q label at the tip."""
    from matplotlib.collections import LineCollection

    for curve in curves:
        alpha = _alpha(curve.q)
        for j, points in enumerate(curve.links):
            xy = view.project(points)
            ax.plot(xy[:, 0], xy[:, 1], color=colours[j], alpha=alpha, lw=1.6)
        for k, segments in enumerate(_triad_segments(curve.joints, arm)):
            flat = view.project(segments.reshape(-1, 3)).reshape(-1, 2, 2)
            # an (n, 2, 2) array is a documented segments argument; the stubs accept only a Sequence
            segments_2d = LineCollection(flat, colors=TRIAD_COLOURS[k], linewidths=0.9, alpha=alpha)  # type: ignore[arg-type]
            ax.add_collection(segments_2d)
        end = view.project(curve.links[-1][-1:])[0]
        ax.annotate(f"q={curve.q:g}", end, xytext=(3, 3), textcoords="offset points", fontsize=7, alpha=alpha)
    ax.set_xlabel(view.labels[0])
    ax.set_ylabel(view.labels[1])
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()


def draw_3d(ax, curves: list[MorphCurve], colours: list, arm: float) -> None:
    """The same curves and triads in a 3-D axes with equal scale on every axis."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    for curve in curves:
        alpha = _alpha(curve.q)
        for j, points in enumerate(curve.links):
            ax.plot(points[:, 0], points[:, 1], points[:, 2], color=colours[j], alpha=alpha, lw=1.6)
        for k, segments in enumerate(_triad_segments(curve.joints, arm)):
            ax.add_collection3d(Line3DCollection(segments, colors=TRIAD_COLOURS[k], linewidths=0.9, alpha=alpha))
    points = np.concatenate([p for c in curves for p in c.links])
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2.0, float(np.max(hi - lo)) / 2.0
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1.0, 1.0, 1.0))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.view_init(elev=20.0, azim=-60.0)


def morph_figure(chain: LinkChain, q_values: list[float]):
    """The figure (three views and a 3-D view) of the centerline at each q in ``q_values``."""
    curves = morph_curves(chain, q_values)
    colours = link_colours(chain.count)
    arm = TRIAD_FRACTION * _extent(curves)
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, GAPS_IN, (2, 2))
        for k, view in enumerate(axis_views()):
            ax = figure.add_subplot(2, 2, k + 1)
            draw_view(ax, curves, view, colours, arm)
            ax.set_title(f"view {view.labels[0][0]}-{view.labels[1][0]}")
        draw_3d(figure.add_subplot(2, 2, 4, projection="3d"), curves, colours, arm)
        handles = [figure.axes[0].plot([], [], color=c, lw=2)[0] for c in colours]
        handles += [figure.axes[0].plot([], [], color=c, lw=1)[0] for c in TRIAD_COLOURS]
        labels = [f"link {j}" for j in range(chain.count)] + ["N", "B", "T"]
        figure.legend(handles, labels, loc="lower center", ncol=min(len(labels), 10), frameon=False)
    return figure


def morph_picture(chain: LinkChain, q_values: list[float]) -> Picture:
    """Figure 1 as a PNG."""
    caption = (
        f"The centerline c(q, l) at the export q = {', '.join(f'{q:g}' for q in q_values)} "
        "(fainter for smaller q), in the input files' coordinates; each link in its own colour. "
        "Triads at every joint show the frame F(q, l) = [N B T c] (N red, B green, T blue) used for "
        "the link transforms S_T_E = inv(F(l_s)) F(l_e)."
    )
    return picture("morph.png", morph_figure(chain, q_values), SIZE_IN, "The morph from q = 0 to q = 1", caption)
