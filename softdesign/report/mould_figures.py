"""An exploded view of a build's casting mould for the report's fabrication section (issue 16).

``mould_picture(data)`` gives None when the build has no mould. The parts are
read from ``meshes/mould/*.stl`` and drawn in the mould frame
(``metrics.mould.frame``): half A lifted along its pull, half B lowered along
its own, the core between them, seen obliquely from the side of half A's cavity
with flat shading (painter's order, back faces culled). No pyplot: an Agg
canvas and PNG metadata without software or time, so the same build gives the
same bytes.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.io.formats import read_mesh
from softdesign.pipeline import layout
from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture
from softdesign.types import FloatArray

#: Figure size, inches, and resolution, dots per inch.
SIZE_IN, DPI = (7.0, 5.0), 100
NAME = "mould.png"
#: Pixel (width, height) of the PNG.
PIXEL_SIZE = (int(round(SIZE_IN[0] * DPI)), int(round(SIZE_IN[1] * DPI)))
#: How far the halves are drawn apart, in heights of the box.
EXPLODE = 0.6
#: Viewing direction (from the eye into the scene) and light, in the mould frame (x along the body, z the pull).
VIEW = np.array([0.45, 1.0, -0.55])
LIGHT = np.array([-0.3, -0.5, 0.8])
COLOURS = {"half_a": "#8fb3d9", "half_b": "#d9b38f", "core": "#9acd8f", "core_plate": "#b0a0c8"}


def _shaded(vertices: FloatArray, faces: np.ndarray, colour: str) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Screen triangles (F, 3, 2), depths (F,) and RGBA colours (F, 4) of the faces turned to the eye."""
    from matplotlib.colors import to_rgba

    view = VIEW / np.linalg.norm(VIEW)
    right = np.cross(view, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, view)
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    front = normal @ view < 0
    tri, normal = tri[front], normal[front]
    light = LIGHT / np.linalg.norm(LIGHT)
    shade = 0.35 + 0.65 * np.clip(normal @ light, 0.0, 1.0)
    rgba = np.tile(to_rgba(colour), (len(tri), 1))
    rgba[:, :3] *= shade[:, None]
    screen = np.stack([tri @ right, tri @ up], axis=-1)
    return screen, tri.mean(axis=1) @ view, rgba


def part_colour(part: str) -> str:
    """A part's colour: the halves', a core's (a single core, each pin of an actuated body), the core plate's."""
    return COLOURS.get(part, COLOURS["core_plate"] if part == "core_plate" else COLOURS["core"])


def mould_figure_png(build_dir: str | Path) -> bytes | None:
    """The exploded view of ``build_dir``'s mould as PNG bytes; None when the build has no mould."""
    build_dir = Path(build_dir)
    manifest = json.loads((build_dir / layout.MANIFEST).read_text(encoding="utf-8"))
    return _exploded_png(build_dir, manifest.get("metrics", {}).get("mould"))


def _exploded_png(build_dir: Path, block: dict[str, Any] | None) -> bytes | None:
    """The picture of the mould the manifest's ``metrics.mould`` ``block`` describes; None without a mould."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    from softdesign.report.flat_triangles import FlatTriangles

    if not block or not block.get("requested"):
        return None
    origin, axes = np.asarray(block["frame"]["origin"]), np.asarray(block["frame"]["axes"])
    parts = {p: read_mesh(build_dir / layout.mould_path(p, "stl")) for p in block["parts"]}
    local = {p: ((np.asarray(v, float) - origin) @ axes.T, np.asarray(f)) for p, (v, f) in parts.items()}
    height = max(float(np.ptp(v[:, 2])) for v, _ in local.values())
    shift = {"half_a": EXPLODE * height, "half_b": -EXPLODE * height}  # a core, the core plate and pins: 0
    screens, depths, colours = [], [], []
    for name, (v, f) in local.items():
        s, d, c = _shaded(v + [0.0, 0.0, shift.get(name, 0.0)], f, part_colour(name))
        screens.append(s)
        depths.append(d)
        colours.append(c)
    screen, depth, rgba = np.concatenate(screens), np.concatenate(depths), np.concatenate(colours)
    order = np.argsort(-depth, kind="stable")  # farthest first
    figure = Figure(figsize=SIZE_IN, dpi=DPI)
    FigureCanvasAgg(figure)
    ax = figure.add_axes((0.02, 0.02, 0.96, 0.9))
    ax.add_artist(FlatTriangles(screen[order], rgba[order]))
    ax.set_xlim(screen[..., 0].min(), screen[..., 0].max())
    ax.set_ylim(screen[..., 1].min(), screen[..., 1].max())
    ax.set_aspect("equal")
    ax.set_axis_off()
    core = block.get("core")
    title = "Casting mould, exploded: half A (pulled up), half B (down)"
    title += f", core ({core['process']})" if core else ""
    figure.suptitle(title, fontsize=9.5)
    labels = dict.fromkeys("cores" if p.startswith("core_") and p != "core_plate" else p for p in local)
    ax.legend(handles=[Patch(color=part_colour(p), label=p) for p in labels], loc="lower right", fontsize=7.5)
    out = io.BytesIO()
    figure.savefig(out, format="png", dpi=DPI, metadata={"Software": None})
    return out.getvalue()


def mould_picture(data: BuildData) -> Picture | None:
    """The exploded view with a caption of the parts' checks; None when the build has no mould."""
    block = data.manifest.get("metrics", {}).get("mould")
    png = _exploded_png(data.build_dir, block)
    if png is None or block is None:
        return None
    cavity, pulls = block["cavity"], block["pull"]
    parts = ", ".join(f"{name} {f['volume_mm3']:.0f} mm3 ({f['faces']} faces)" for name, f in block["parts"].items())
    caption = (
        f"Parts in meshes/mould/: {parts}. The cavity they leave differs from the q = 0 body by "
        f"{100 * cavity['rel_difference']:.2g} % of its volume (limit {100 * cavity['tolerance']:g} %); parts "
        f"disjoint: {'yes' if block['disjoint']['ok'] else 'NO'}; "
        + "; ".join(f"{k} pulls off: {'yes' if p['ok'] else 'NO'} ({p['against_pull']} faces against the pull, "
                    f"{p['blocked_rays']} rays blocked)" for k, p in pulls.items())
        + (f". Core: {block['core']['process']}: {block['core']['note']}" if block.get("core") else "")
        + "."
    )
    return Picture(NAME, png, PIXEL_SIZE, "Casting mould (exploded view)", caption)
