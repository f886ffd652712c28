"""Figure: the skin's principal stretches unrolled in (l, a) at q = 1 and at the worst q, on the 3D body, and the wall.

The stretches are those of the feasibility stage (:mod:`softdesign.fitting.strain`,
rest state q = 0), evaluated on a regular (l, a) grid for drawing; the
worst q is the one of the morph's extreme (``metrics.feasibility.morph``)
farthest from 1 in log-stretch.  A hollow body adds its wall thickness at q = 1
(:func:`softdesign.meshing.body.wall.wall_map`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.fitting.strain import principal_stretches, skin_metric
from softdesign.meshing.body.wall import wall_map
from softdesign.meshing.volume import BodySpec
from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture, fixed_figure, picture, styled
from softdesign.report.projection import shaded_triangles
from softdesign.report.surface_figures import final_view, tube_mesh
from softdesign.types import FloatArray

SIZE_IN = (13.0, 8.0)
#: Fixed layout of the 2 x 3 panels, inches: margins (left, right, bottom, top) and gaps (columns, rows); each
#: panel's colour bar is taken from its own cell, so the gaps hold the bar's ticks and the next panel's labels.
MARGINS_IN, GAPS_IN = (0.75, 0.5, 0.45, 0.3), (1.2, 0.75)
#: Drawing grid: spacing along the centerline (mm) and angles around.
MAP_SPACING_MM = 0.5
MAP_ANGLES = 96
NAME = "stretch.png"


def worst_q(block: dict[str, Any]) -> float:
    """The q of the morph's extreme stretch farthest from 1 (in |log lambda|)."""
    morph = block["morph"]
    high, low = morph["stretch_max"], morph["stretch_min"]
    return float(high["q"] if abs(np.log(high["value"])) >= abs(np.log(low["value"])) else low["q"])


def stretch_grid(data: BuildData, q: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """l (p,), a (m,) rad, lambda1 and lambda2 (p, m) of the outer skin at q against q = 0."""
    assert data.fit is not None
    shape, field = data.kinematics.chain.shape, data.fit.field
    frames = str(data.manifest.get("case", {}).get("frames", "rmf"))
    count = max(int(np.ceil(shape.keys[-1].length / MAP_SPACING_MM)), 8) + 1
    l = np.linspace(0.0, 1.0, count)
    a = np.linspace(0.0, 2.0 * np.pi, MAP_ANGLES, endpoint=False)
    rest = skin_metric(shape.curve_at(0.0), field, 0.0, l, a, frames)
    lam1, lam2 = principal_stretches(rest, skin_metric(shape.curve_at(q), field, q, l, a, frames))
    return l, a, lam1, lam2


def _unrolled(ax, l, a, values, breaks, title: str, cmap: str, limits: tuple[float, float]):
    mesh = ax.pcolormesh(l, np.degrees(a), values.T, shading="nearest", cmap=cmap, vmin=limits[0], vmax=limits[1])
    for b in breaks[1:-1]:
        ax.axvline(b, color="k", linewidth=0.6, linestyle="--")
    ax.set_xlabel("l (normalized; dashed: joints)")
    ax.set_ylabel("angle a (deg, from N towards B)")
    ax.set_title(title)
    return mesh


def _spec(data: BuildData) -> BodySpec:
    export = data.manifest.get("case", {}).get("export", {})
    return BodySpec(offset_mm=float(export.get("offset_mm") or 0.0), wall_mm=float(export.get("wall_mm") or 0.0),
                    port_mm=float(export.get("port_mm") or 0.0))


def stretch_picture(data: BuildData) -> Picture | None:
    """The figure, or None when the build has no fit or no feasibility figures."""
    block = data.manifest.get("metrics", {}).get("feasibility")
    if data.fit is None or not isinstance(block, dict):
        return None
    breaks = np.asarray(data.fit.field.breaks, float)
    q_worst = worst_q(block)
    grids = {q: stretch_grid(data, q) for q in sorted({1.0, q_worst})}
    high = max(float(g[2].max()) for g in grids.values())
    low = min(float(g[3].min()) for g in grids.values())
    spec = _spec(data)
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, GAPS_IN, (2, 3))
        axes = figure.subplots(2, 3)
        for row, q in enumerate((1.0, q_worst)):
            l, a, lam1, lam2 = grids[q]
            m1 = _unrolled(axes[row, 0], l, a, lam1, breaks, f"lambda1 at q = {q:.3f}", "magma", (1.0, max(high, 1.0)))
            m2 = _unrolled(axes[row, 1], l, a, lam2, breaks, f"lambda2 at q = {q:.3f}", "viridis", (min(low, 1.0), 1.0))
            figure.colorbar(m1, ax=axes[row, 0])
            figure.colorbar(m2, ax=axes[row, 1])
        _body(figure, axes[0, 2], data, grids[1.0])
        _wall_panel(figure, axes[1, 2], data, spec)
    caption = (
        "Principal stretches of the outer skin against the body cast at q = 0 (lambda1 >= lambda2; 1 is unstretched), "
        f"unrolled per link in (l, a) at q = 1 and at the morph's worst q = {q_worst:.3f}; top right: lambda1 at "
        "q = 1 on the body; bottom right: the wall thickness of a hollow body at q = 1 (true distance from the "
        "chamber to the outer mesh)."
    )
    return picture(NAME, figure, SIZE_IN, "Skin stretch and wall thickness", caption)


def _body(figure, ax, data: BuildData, grid) -> None:
    """lambda1 at q = 1 painted on the tube, seen as the surfaces figure sees it."""
    import matplotlib

    from softdesign.report.flat_triangles import add_triangles

    assert data.fit is not None
    chain = data.kinematics.chain
    l, a, lam1, _ = grid
    vertices, faces, _ = tube_mesh(chain, data.fit.field, 1.0, MAP_SPACING_MM, MAP_ANGLES)
    view = final_view(chain)
    shaded = shaded_triangles(vertices, faces, view)
    # each face's ring and angle: faces come in two blocks of (rings - 1) x angles cells
    cells = len(faces) // 2
    cell = shaded.face_index % cells
    values = lam1[cell // MAP_ANGLES, cell % MAP_ANGLES]
    norm = matplotlib.colors.Normalize(1.0, max(float(lam1.max()), 1.0))
    colours = matplotlib.colormaps["magma"](norm(values))[:, :3] * shaded.brightness[:, None]
    add_triangles(ax, shaded.triangles, colours)
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_title("lambda1 at q = 1 on the body")
    figure.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap="magma"), ax=ax)


def _wall_panel(figure, ax, data: BuildData, spec: BodySpec) -> None:
    if spec.wall_mm <= 0 or data.fit is None:
        ax.axis("off")
        ax.text(0.5, 0.5, "solid body: no wall", ha="center", va="center", transform=ax.transAxes)
        return
    export = data.manifest.get("case", {}).get("export", {})
    walls = wall_map(data.kinematics.chain.shape.curve_at(1.0), data.fit.field, 1.0, spec,
                     float(export.get("spacing_mm", 0.5)), int(export.get("angular_count", 64)))
    mesh = _unrolled(ax, walls.l, walls.a, walls.thickness_mm, np.asarray(data.fit.field.breaks), "wall at q = 1 (mm)",
                     "cividis", (float(walls.thickness_mm.min()), float(walls.thickness_mm.max())))
    figure.colorbar(mesh, ax=ax)
