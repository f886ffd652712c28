"""Figure 6, the morph as an animated GIF from q = 0 to q = 1 (Pillow).

Each frame is the actuator's tube S(q) tessellated from the radius field,
shaded and coloured by link, seen along the final centerline's direction of
least spread (as the surface figure), at one scale for every frame.  Without
a fit the frames show the centerline alone.  One matplotlib figure is drawn
once without the actuator and the title; each frame restores that canvas and
draws only them over it (blitting: the axes, ticks and labels are not laid out
and drawn again 26 times, most of a frame's cost).  The frames are quantized
without dithering, so the file is small and the same build gives the same bytes.
"""

from __future__ import annotations

import io

import numpy as np

from softdesign.fitting.radius_field import RadiusField
from softdesign.kinematics.links import LinkChain
from softdesign.report.plotting import DPI, Picture, link_colours, new_figure, styled
from softdesign.report.projection import View, bounding_limits, shaded_triangles
from softdesign.report.surface_figures import final_view, tube_mesh
from softdesign.types import FloatArray

SIZE_IN = (6.4, 4.0)
#: Frames from q = 0 to q = 1, both included.
FRAMES = 26
#: Display time of a frame and of the first and last (held) frames, ms.
FRAME_MS, HOLD_MS = 90, 900
#: Palette size of each frame (fewer colours compress better; shading needs a few dozen).
GIF_COLOURS = 64
#: Tube tessellation of a frame: spacing along the centerline (mm) and angles around (coarser than the still).
TUBE_SPACING_MM, TUBE_ANGLES = 1.0, 32
#: Centerline samples per frame when the build has no fit.
CURVE_SAMPLES = 200


def frame_q(frames: int = FRAMES) -> FloatArray:
    """The q of every frame, evenly spaced from 0 to 1."""
    return np.linspace(0.0, 1.0, int(frames))


def _frame_geometry(chain: LinkChain, field: RadiusField | None, q: float, view: View):
    """Screen triangles (k, 3, 2) and their RGB (k, 3) at q, or the centerline as a polyline (m, 2) and None."""
    if field is None:
        return view.project(chain.shape.curve_at(q).points(np.linspace(0.0, 1.0, CURVE_SAMPLES))), None
    vertices, faces, face_l = tube_mesh(chain, field, q, TUBE_SPACING_MM, TUBE_ANGLES)
    shaded = shaded_triangles(vertices, faces, view, cull=True)
    colours = np.array(link_colours(chain.count))[:, :3][field.link_of(face_l[shaded.face_index])]
    return shaded.triangles, np.clip(shaded.brightness[:, None] * colours, 0.0, 1.0)


def morph_frames(chain: LinkChain, field: RadiusField | None, frames: int = FRAMES) -> list:
    """The frames as RGB Pillow images of :data:`SIZE_IN` at :data:`DPI`."""
    from softdesign.report.flat_triangles import FlatTriangles

    view = final_view(chain)
    geometry = [(q, *_frame_geometry(chain, field, float(q), view)) for q in frame_q(frames)]
    xlim, ylim = bounding_limits([g[1].reshape(-1, 2) for g in geometry])
    with styled():
        figure = new_figure(SIZE_IN)
        ax = figure.add_subplot(1, 1, 1)
        ax.update_datalim([(xlim[0], ylim[0]), (xlim[1], ylim[1])])  # every frame inside, at one scale
        ax.set_aspect("equal", adjustable="datalim")
        ax.autoscale_view()
        ax.set(xlabel=view.labels[0], ylabel=view.labels[1])
        artist = ax.plot([], [], color="k", lw=2.0)[0] if field is None else ax.add_artist(
            FlatTriangles(np.zeros((0, 3, 2)), np.zeros((0, 3)))
        )
        background = _background(figure, ax, artist, geometry[0])
        return [_draw_frame(figure, ax, artist, background, frame) for frame in geometry]


def _set_frame(ax, artist, frame) -> None:
    """Put this frame's geometry in the one artist and its q in the title."""
    q, shape, colours = frame
    if colours is None:
        artist.set_data(shape[:, 0], shape[:, 1])
    else:
        artist.set_data(shape, colours)
    ax.set_title(f"q = {q:.2f}")


def _background(figure, ax, artist, first) -> object:
    """The canvas without the moving artist and the title, drawn once for every frame.

    The layout is solved with the first frame in place (title included) and then frozen: every frame has the
    same axes, ticks and labels, so only the artist and the title are drawn per frame.
    """
    _set_frame(ax, artist, first)
    figure.canvas.draw()
    figure.set_layout_engine("none")
    artist.set_visible(False)
    ax.title.set_visible(False)
    figure.canvas.draw()
    artist.set_visible(True)
    ax.title.set_visible(True)
    return figure.canvas.copy_from_bbox(figure.bbox)


def _draw_frame(figure, ax, artist, background, frame) -> object:
    """Restore the drawn axes, draw this frame's artist and title over them, grab the canvas as an RGB image."""
    from PIL import Image

    _set_frame(ax, artist, frame)
    figure.canvas.restore_region(background)
    ax.draw_artist(artist)
    ax.draw_artist(ax.title)
    return Image.fromarray(np.asarray(figure.canvas.buffer_rgba())[:, :, :3].copy())


def gif_bytes(images: list) -> bytes:
    """An endlessly looping GIF of the frames, first and last held longer."""
    from PIL import Image

    paletted = [
        im.quantize(colors=GIF_COLOURS, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE) for im in images
    ]
    durations = [HOLD_MS if k in (0, len(images) - 1) else FRAME_MS for k in range(len(images))]
    buffer = io.BytesIO()
    paletted[0].save(buffer, format="GIF", save_all=True, append_images=paletted[1:], duration=durations, loop=0)
    return buffer.getvalue()


def morph_gif(chain: LinkChain, field: RadiusField | None, frames: int = FRAMES) -> Picture:
    """Figure 6: the animated morph."""
    data = gif_bytes(morph_frames(chain, field, frames))
    what = "the actuator's surface, coloured by link" if field is not None else "the centerline (no fit in this build)"
    caption = (
        f"{frames} frames from q = 0 to q = 1 of {what}, seen as in the surface figure, at one scale; "
        "the first and last frames are held."
    )
    size = (int(round(SIZE_IN[0] * DPI)), int(round(SIZE_IN[1] * DPI)))
    return Picture("morph.gif", data, size, "The morph, animated", caption)
