"""The interactive 3D view (issue 17, item 2): the actuator morphing over q with a slider and play, in plotly.

One plotly figure: the actuator's tube S(q) tessellated from the radius field
(faces coloured by link), the centerline c(q) per link (in the legend), and the
patient's vessel surface, semi-transparent, around the q = 1 body.  The frames
(one per q) change only the actuator and the centerline; the scene's ranges are
fixed over every frame so the camera does not jump.  A frame changes only the
vertices of a mesh, so the tube has the same ring count at every q (rings
:data:`SPACING_MM` apart, or closer, on the longest c(q)).  A build with a
casting mould or a hollow body adds them, hidden until clicked in the legend
(:mod:`softdesign.report.interactive_parts`); the ranges include the mould.

For display only, the tube is tessellated coarser than the export
(:data:`SPACING_MM`, :data:`ANGLES`) and the vessel surface is decimated
(:func:`softdesign.report.display_mesh.decimated_vessel`, at most its
``VESSEL_FACES`` triangles), both within :data:`DISPLAY_TOLERANCE_MM`: the display error (the largest distance
from the fine surface's points to the displayed mesh, mm) is measured, and
while it exceeds the tolerance the tube's rings and angles are doubled (at
most :data:`MAX_REFINEMENTS` times) and the vessel keeps twice the triangles.
The caption states both measured errors.  Coordinates are written as
float32 (0.01 um at 100 mm, far below those errors).

The figure is a plain dict of plotly trace dicts (``{"type": "mesh3d", ...}``),
written by :func:`plotly.io.to_html` unvalidated: plotly's figure classes
(``plotly.graph_objects``) would check every property of every trace and
frame, about half the view's time, for a figure this module writes whole.  Its
numpy arrays are written as plotly writes a figure's arrays (base64 typed
arrays, :func:`_plotly_utils.utils.convert_to_base64`), and layout.template is
:data:`TEMPLATE_NONE`, the JSON of plotly's template ``"none"``.

plotly (MIT licence) ships plotly.js; the report writes it once as the file
:data:`JS_NAME` beside the page, so the view needs no network.  The figure's
div has a fixed id and plotly writes no time or random id: the same build gives
the same bytes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softdesign.report import interactive_parts
from softdesign.report.build_folder import BuildData
from softdesign.report.display_mesh import (
    DISPLAY_TOLERANCE_MM,
    max_distance_to_mesh,
)
from softdesign.report.plotting import link_colours
from softdesign.report.surface_figures import VESSEL_RGB, tube_mesh
from softdesign.types import FloatArray

#: plotly.js, written beside the page.
JS_NAME = "plotly.min.js"
#: The fixed id of the figure's element.
DIV_ID = "morph3d"
#: Frames from q = 0 to q = 1, both included.
FRAMES = 21
#: Display tessellation of the tube: ring spacing along the centerline (mm) and vertices around.
SPACING_MM, ANGLES = 1.0, 32
#: The fine tessellation the display error is measured against: half the display's spacing and angle, so its
#: points include every displayed cell's edge midpoints and centre, where a chord strays farthest from the surface.
FINE_FACTOR = 2
#: The tube is refined at most this many times (each doubles rings and angles: 4x the page's tube data).
MAX_REFINEMENTS = 2
#: Centerline samples per link and frame.
CURVE_SAMPLES = 40
VESSEL_OPACITY = 0.25
#: Runs the play and pause buttons' animations.  Pause interrupts play, and plotly.js rejects the interrupted
#: animation's promise with no reason; a button that calls plotly itself logs "API call to Plotly.animate
#: rejected" and leaves the rejection uncaught (an "Uncaught (in promise)" error in the console).  The buttons
#: only emit plotly_buttonclicked ("execute": false) and this handler animates, dropping that one rejection and
#: re-raising any other.  ``{plot_id}`` is plotly's placeholder for the figure's element id.  The page does not
#: play on load (plotly's ``auto_play``, whose animation's promise nothing catches either: pausing it, or dragging
#: the slider while it plays, logged the same error); it opens on q = 1.
BUTTON_SCRIPT = """var gd = document.getElementById('{plot_id}');
gd.on('plotly_buttonclicked', function (event) {
  if (event.button.method !== 'animate') { return; }
  Plotly.animate(gd, event.button.args[0], event.button.args[1]).catch(function (reason) {
    if (reason !== undefined) { throw reason; }
  });
});"""
HEIGHT_PX = 720
#: The figure's margins, px: room below the plot for the slider and its labels, and on the right for its last one
#: (with none, the labels were cut at the bottom and "1.00" at the right).
MARGIN_PX = (("l", 0), ("r", 40), ("t", 30), ("b", 120))
#: The slider's start and length in the figure's width (its end stays inside the right margin).
SLIDER_X, SLIDER_LEN = 0.1, 0.85
#: The camera's distance from the box's centre in plotly's scene units (the box's longest side is 1 long), and its
#: tilt towards the box's longest and middle sides (see :func:`fitted_camera`).
CAMERA_DISTANCE = 1.3
CAMERA_TILT = (0.25, 0.45)
#: Ticks on the box's longest side (fewer on the others, in proportion).
MAX_TICKS = 8
#: plotly's template ``"none"`` (no styling: plotly.js's own defaults) as plotly's figure classes wrote it in the
#: layout: plotly's Python side keeps one empty scatter style in it, as it takes an empty template for none given.
TEMPLATE_NONE: dict[str, Any] = {"data": {"scatter": [{"type": "scatter"}]}}


def tube_display_error_mm(data: BuildData, q: float = 1.0, spacing_mm: float = SPACING_MM,
                          angles: int = ANGLES) -> float:
    """Largest distance from the fine tube's vertices at ``q`` to the displayed (coarse) tube, mm."""
    assert data.fit is not None
    chain, field = data.kinematics.chain, data.fit.field
    coarse_vertices, coarse_faces, _ = tube_mesh(chain, field, q, spacing_mm, angles)
    fine_vertices, _, _ = tube_mesh(chain, field, q, spacing_mm / FINE_FACTOR, angles * FINE_FACTOR)
    return max_distance_to_mesh(fine_vertices, coarse_vertices, coarse_faces)


def display_tube(data: BuildData, tolerance_mm: float = DISPLAY_TOLERANCE_MM) -> tuple[float, int, float]:
    """(ring spacing mm, vertices around, display error mm at q = 1): the coarsest tube within ``tolerance_mm``
    (or the finest of :data:`MAX_REFINEMENTS` refinements)."""
    spacing, angles = SPACING_MM, ANGLES
    error = tube_display_error_mm(data, 1.0, spacing, angles)
    for _ in range(MAX_REFINEMENTS):
        if error <= tolerance_mm:
            break
        spacing, angles = spacing / 2, angles * 2
        error = tube_display_error_mm(data, 1.0, spacing, angles)
    return spacing, angles, error


def _rgb(colour) -> str:
    return "rgb({:d},{:d},{:d})".format(*(int(round(255 * c)) for c in colour[:3]))


def tube_rings(data: BuildData, q_values: FloatArray, spacing_mm: float) -> int:
    """Rings of the displayed tube at every q: ``spacing_mm`` apart (or closer) on the longest c(q) of ``q_values``.

    One count for every frame, so that every frame has the faces of the trace it updates.
    """
    longest = max(data.kinematics.chain.shape.curve_at(float(q)).length for q in q_values)
    return max(int(np.ceil(longest / spacing_mm)), 8) + 1


def _frame_traces(data: BuildData, q: float, spacing_mm: float = SPACING_MM, angles: int = ANGLES,
                  rings: int | None = None) -> list[dict[str, Any]]:
    """The traces that change with q: the tube (when fitted, ``rings`` rings), then one centerline trace per link."""
    chain = data.kinematics.chain
    curve = chain.shape.curve_at(q)
    traces: list[dict[str, Any]] = []
    if data.fit is not None:
        vertices, _, _ = tube_mesh(chain, data.fit.field, q, spacing_mm, angles, rings)
        v = vertices.astype(np.float32)
        traces.append({"x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "type": "mesh3d"})
    for j in range(chain.count):
        p = curve.points(np.linspace(chain.breaks[j], chain.breaks[j + 1], CURVE_SAMPLES)).astype(np.float32)
        traces.append({"x": p[:, 0], "y": p[:, 1], "z": p[:, 2], "type": "scatter3d"})
    return traces


def morph_figure(data: BuildData, frames: int = FRAMES) -> tuple[dict[str, Any], list[str]]:
    """The plotly figure as a dict (data, layout, frames) and the notes on what was decimated (display errors, mm)."""
    chain = data.kinematics.chain
    colours = [_rgb(c) for c in link_colours(chain.count)]
    q_values = np.linspace(0.0, 1.0, int(frames))
    spacing, angles, tube_error = display_tube(data) if data.fit is not None else (SPACING_MM, ANGLES, 0.0)
    rings = tube_rings(data, q_values, spacing)
    per_q = [_frame_traces(data, float(q), spacing, angles, rings) for q in q_values]
    first = per_q[-1]  # the page opens on q = 1, inside the vessel
    traces: list[dict[str, Any]] = []
    notes: list[str] = []
    if data.fit is not None:
        _, faces, face_l = tube_mesh(chain, data.fit.field, 1.0, spacing, angles, rings)
        face_colours = np.array(colours, dtype=object)[data.fit.field.link_of(face_l)]
        traces.append({"facecolor": face_colours, "flatshading": False, "hoverinfo": "skip", "i": faces[:, 0],
                       "j": faces[:, 1], "k": faces[:, 2], "name": "actuator", "showlegend": True,
                       **{k: first[0][k] for k in "xyz"}, "type": "mesh3d"})
        notes.append(f"actuator: {spacing:g} mm rings, {angles} vertices around; display error at q = 1 "
                     f"{tube_error:.3f} mm (against {FINE_FACTOR}x finer; tolerance {DISPLAY_TOLERANCE_MM:g} mm)")
    for j, trace in enumerate(first[len(first) - chain.count:]):
        traces.append({"hoverinfo": "name", "line": {"color": colours[j], "width": 6}, "mode": "lines",
                       "name": f"link {j} (centerline)", **{k: trace[k] for k in "xyz"}, "type": "scatter3d"})
    chamber = interactive_parts.chamber_frames(data, q_values, FINE_FACTOR, DISPLAY_TOLERANCE_MM)
    if chamber is not None and chamber.frames:
        for frame, trace in zip(per_q, chamber.frames, strict=True):
            frame.append(trace)
        traces.append(interactive_parts.chamber_trace(chamber))
    notes.extend(chamber.notes if chamber is not None else [])
    moving = list(range(len(traces)))
    if len(data.ingest.faces):
        v, f, error = data.vessel_display
        v = v.astype(np.float32)
        traces.append({"color": _rgb(VESSEL_RGB), "hoverinfo": "skip", "i": f[:, 0], "j": f[:, 1], "k": f[:, 2],
                       "name": "patient's vessel (input)", "opacity": VESSEL_OPACITY, "showlegend": True,
                       "x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "type": "mesh3d"})
        notes.append(f"vessel: {len(f)} of {len(data.ingest.faces)} triangles; display error {error:.3f} mm "
                     f"(tolerance {DISPLAY_TOLERANCE_MM:g} mm)")
    mould, mould_notes = interactive_parts.mould_traces(data, DISPLAY_TOLERANCE_MM)
    traces.extend(mould)
    notes.extend(mould_notes)
    figure = {"data": traces, "layout": _layout(per_q, traces, q_values), "frames": [
        {"data": per_q[k], "name": f"{q:.3f}", "traces": moving} for k, q in enumerate(q_values)
    ]}
    return figure, notes


def _layout(per_q: list[list[dict[str, Any]]], traces: list[dict[str, Any]], q_values: FloatArray
            ) -> dict[str, Any]:
    """Fixed scene ranges over every frame and the vessel, a q slider and a play button."""
    points = [np.column_stack([t["x"], t["y"], t["z"]]) for frame in per_q for t in frame]
    # the mould too (hidden at first): it encloses the q = 0 body with export.mould.margin_mm, so the box grows by
    # about that margin on each side, and the mould is not cut by the box when shown
    points += [np.column_stack([t["x"], t["y"], t["z"]]) for t in traces
               if t.get("name", "").startswith(("patient", interactive_parts.MOULD_PREFIX))]
    stacked = np.concatenate(points).astype(float)
    low, high = stacked.min(axis=0), stacked.max(axis=0)
    span = np.maximum(high - low, 1e-6)
    pad = 0.03 * span.max()
    ratio = (span + 2 * pad) / (span + 2 * pad).max()
    axes = {name: {"title": {"text": f"{name} (mm)"}, "range": [float(low[i] - pad), float(high[i] + pad)],
                   "nticks": _tick_count(ratio[i])}
            for i, name in enumerate(("x", "y", "z"))}
    animate = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}, "transition": {"duration": 0}}
    # The slider queues its frames ("afterall") rather than interrupting the one being drawn: plotly.js rejects an
    # interrupted animation's promise and nothing catches it, so every step dragged over logged "Uncaught (in
    # promise)" in the browser's console.  Pause must interrupt play (mode "immediate"), as plotly documents, which
    # rejects play's promise: the buttons do not call plotly themselves ("execute": False) but :data:`BUTTON_SCRIPT`
    # does, catching that rejection.
    queued = {**animate, "mode": "afterall"}
    steps = [{"args": [[f"{q:.3f}"], queued], "label": f"{q:.2f}", "method": "animate"} for q in q_values]
    play = {"frame": {"duration": 120, "redraw": True}, "fromcurrent": True, "transition": {"duration": 0}}
    # keys in the order plotly's figure classes wrote them, so that the page's bytes did not change with them
    return {
        "template": TEMPLATE_NONE, "margin": dict(MARGIN_PX), "legend": {"x": 0.0, "y": 1.0},
        "scene": {**{f"{k}axis": v for k, v in axes.items()},
                  "aspectratio": {k: float(r) for k, r in zip("xyz", ratio, strict=True)}, "aspectmode": "manual",
                  "camera": fitted_camera(ratio)},
        "height": HEIGHT_PX,
        "sliders": [{"active": len(q_values) - 1, "currentvalue": {"prefix": "q = "}, "len": SLIDER_LEN,
                     "pad": {"t": 20}, "steps": steps, "x": SLIDER_X}],
        "updatemenus": [{"buttons": [{"args": [None, play], "execute": False, "label": "play", "method": "animate"},
                                     {"args": [[None], animate], "execute": False, "label": "pause",
                                      "method": "animate"}],
                         "pad": {"t": 20}, "showactive": False, "type": "buttons", "x": 0.0, "xanchor": "left",
                         "y": 0.0, "yanchor": "top"}],
    }


def fitted_camera(ratio: FloatArray) -> dict[str, Any]:
    """A camera that shows the scene's box large: its longest side across the page's wide panel.

    The eye looks mostly along the box's shortest side, tilted a little towards the others so the view stays
    three-dimensional; "up" is the middle side, so the longest one runs left to right, the panel's long way.
    plotly's default eye, (1.25, 1.25, 1.25) for every box, stood far back along the diagonal: a long thin body
    filled a small part of the panel.  ``ratio`` is the box's aspect ratio (3,), largest side 1.
    """
    order = np.argsort(ratio, kind="stable")  # shortest, middle, longest
    axes = np.eye(3)
    direction = CAMERA_TILT[0] * axes[order[2]] + CAMERA_TILT[1] * axes[order[1]] + axes[order[0]]
    eye = CAMERA_DISTANCE * direction / np.linalg.norm(direction)
    up = axes[order[1]]
    return {"eye": dict(zip("xyz", (float(v) for v in eye), strict=True)),
            "up": dict(zip("xyz", (float(v) for v in up), strict=True)),
            "center": {"x": 0.0, "y": 0.0, "z": 0.0}}


def _tick_count(ratio: float) -> int:
    """Ticks on an axis whose side is ``ratio`` of the longest: few on short sides, so their labels stay apart."""
    return max(2, int(round(MAX_TICKS * float(ratio))))


def morph_html(data: BuildData, frames: int = FRAMES) -> tuple[str, list[str]]:
    """The figure's HTML fragment (a div and its script; plotly.js is :data:`JS_NAME`) and the display notes."""
    from _plotly_utils.utils import convert_to_base64
    from plotly.io import to_html

    figure, notes = morph_figure(data, frames)
    convert_to_base64(figure)  # numpy arrays as plotly writes a figure's: base64 typed arrays
    html = to_html(figure, validate=False, include_plotlyjs=False, full_html=False, div_id=DIV_ID,
                   config={"displaylogo": False, "responsive": True}, post_script=BUTTON_SCRIPT, auto_play=False)
    return f'<script src="{JS_NAME}" charset="utf-8"></script>\n{html}', notes


def plotly_js() -> bytes:
    """plotly.js as plotly's Python package ships it (the same bytes for one plotly version)."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs().encode("utf-8")
