"""The fabrication parts of the interactive 3D view: the casting mould and a hollow body's chamber (issue 17, item 2).

Both are hidden when the page opens (plotly's ``visible="legendonly"``: a click
on their legend entry shows them), so the default view stays the actuator over
the vessel.

Mould
    The parts the mould stage wrote (``meshes/mould/{half_a,half_b,core}.stl``,
    the parts ``metrics.mould.parts`` lists), where they are cast: around the
    q = 0 body.  They do not move with q.  Each is decimated for display as the
    vessel is (:func:`softdesign.report.display_mesh.decimated_surface`, at most
    :data:`MOULD_FACES` triangles, within the view's display tolerance), the
    measured error stated.
Chamber
    A hollow body's chamber (``export.wall_mm`` > 0) as the exporter builds it:
    the inward offset of the outer surface by ``wall_mm``, trimmed ``wall_mm``
    short of both ends (:func:`softdesign.meshing.solids._chamber`, the same
    function the wall-thickness map uses), tessellated with end caps at the
    display tube's ring spacing and angles, at every frame's q (it morphs with
    the actuator).  Its display error at q = 1 is measured as the tube's is,
    against a :data:`~softdesign.report.interactive.FINE_FACTOR` times finer
    chamber.  The port channel is not drawn (the cross-sections show it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.errors import MeshError
from softdesign.io.formats import read_mesh
from softdesign.meshing.volume import BodySpec
from softdesign.pipeline import layout
from softdesign.report.build_folder import BuildData
from softdesign.report.display_mesh import decimated_surface, max_distance_to_mesh
from softdesign.report.mould_figures import COLOURS as MOULD_COLOURS
from softdesign.report.mould_figures import part_colour
from softdesign.types import FloatArray

#: At most this many triangles of each mould part are shown (more only to meet the display tolerance).
MOULD_FACES = 4000
MOULD_OPACITY = 0.35
CHAMBER_RGB = "rgb(214,39,40)"
#: The display chamber's first grid: ring spacing along the centerline (mm) and vertices around; refined at most
#: :data:`CHAMBER_REFINEMENTS` times (each doubles both) while it misses the display tolerance.
CHAMBER_SPACING_MM, CHAMBER_ANGLES, CHAMBER_REFINEMENTS = 2.0, 24, 3
#: Samples of the arc length table that places the chamber's rings.
ARC_SAMPLES = 2001
#: Names of the traces (the legend's entries; the page test looks for them).
MOULD_PREFIX = "casting mould: "
CHAMBER_NAME = "chamber (hollow body)"


def mould_block(data: BuildData) -> dict[str, Any] | None:
    """The manifest's ``metrics.mould`` when the build has a mould, else None."""
    block = data.manifest.get("metrics", {}).get("mould")
    return block if isinstance(block, dict) and block.get("requested") else None


def mould_traces(data: BuildData, tolerance_mm: float) -> tuple[list[dict[str, Any]], list[str]]:
    """The mould's parts as hidden plotly mesh3d trace dicts (none without a mould) and notes on their display error."""
    block = mould_block(data)
    if block is None:
        return [], []
    traces: list[dict[str, Any]] = []
    notes: list[str] = []
    order = list(MOULD_COLOURS)  # halves, core, core plate; an actuated body's pins after them by name
    for part in sorted(block["parts"], key=lambda p: (order.index(p) if p in order else len(order), p)):
        vertices, faces = read_mesh(data.build_dir / layout.mould_path(part, "stl"))
        v, f, error = decimated_surface(vertices, faces, MOULD_FACES, tolerance_mm)
        v = v.astype(np.float32)
        traces.append({"color": part_colour(part), "flatshading": True, "hoverinfo": "name", "i": f[:, 0],
                       "j": f[:, 1], "k": f[:, 2], "name": MOULD_PREFIX + part, "opacity": MOULD_OPACITY,
                       "showlegend": True, "visible": "legendonly", "x": v[:, 0], "y": v[:, 1], "z": v[:, 2],
                       "type": "mesh3d"})
        notes.append(f"mould {part}: {len(f)} of {len(faces)} triangles, display error {error:.3f} mm")
    return traces, notes


def body_spec(data: BuildData) -> BodySpec:
    """The body the export made: ``export.offset_mm``, ``wall_mm`` and ``port_mm`` from the manifest's case."""
    export = data.manifest.get("case", {}).get("export", {})
    return BodySpec(offset_mm=float(export.get("offset_mm") or 0.0), wall_mm=float(export.get("wall_mm") or 0.0),
                    port_mm=float(export.get("port_mm") or 0.0))


def chamber_mesh(data: BuildData, q: float, rings: int, angles: int) -> tuple[FloatArray, np.ndarray]:
    """Vertices (V, 3) mm and faces (F, 3) of the chamber at ``q``: ``rings`` rings evenly spaced in arc length.

    The exporter's chamber (the sections offset inwards by ``wall_mm``,
    :func:`softdesign.meshing.tessellate.sweep_from_sections`, between arc lengths ``wall_mm`` and
    ``length - wall_mm``) on a grid of ``rings`` x ``angles`` at every q, so every frame has the same faces.

    Raises
    ------
    MeshError
        As the export would at this q: a fold, or a wall the local radius cannot take.
    """
    from softdesign.meshing.body.sections import sections_on_grid
    from softdesign.meshing.tessellate import sweep_from_sections, tessellate
    from softdesign.meshing.volume import angle_grid

    assert data.fit is not None
    spec, field = body_spec(data), data.fit.field
    curve = data.kinematics.chain.shape.curve_at(q)
    dense = np.linspace(0.0, 1.0, ARC_SAMPLES)
    s = curve.curve.arc_length(dense)
    if s[-1] - 2.0 * spec.wall_mm < spec.min_radius_mm:
        raise MeshError(f"wall_mm: at q={q:.3f} a wall of {spec.wall_mm:g} mm at both ends of a body {s[-1]:.3f} mm "
                        "long leaves no chamber")
    l = np.interp(np.linspace(spec.wall_mm, s[-1] - spec.wall_mm, rings), s, dense)
    a = angle_grid(angles)
    sections = sections_on_grid(curve, q, l, field.evaluate_grid(q, l, a), field.evaluate_grid(q, l, a, dl=1))
    mesh = tessellate(sweep_from_sections(sections, spec.offset_mm - spec.wall_mm, spec.min_radius_mm, "wall_mm"))
    return mesh.vertices, mesh.faces


def chamber_rings(data: BuildData, q_values: FloatArray, spacing_mm: float) -> int:
    """Rings of the display chamber: ``spacing_mm`` apart (or closer) on the longest chamber over ``q_values``."""
    chain, wall = data.kinematics.chain, body_spec(data).wall_mm
    longest = max(chain.shape.curve_at(float(q)).length for q in q_values) - 2.0 * wall
    return max(int(np.ceil(longest / spacing_mm)), 2) + 1


def display_chamber(data: BuildData, q_values: FloatArray, tolerance_mm: float, fine_factor: int
                    ) -> tuple[int, int, float]:
    """(rings, angles, display error mm at q = 1): the coarsest chamber grid within ``tolerance_mm``.

    Starts at :data:`CHAMBER_SPACING_MM` and :data:`CHAMBER_ANGLES` and doubles both (at most
    :data:`CHAMBER_REFINEMENTS` times) while the largest distance from a ``fine_factor`` times finer chamber's
    vertices to it exceeds the tolerance.
    """
    spacing, angles = CHAMBER_SPACING_MM, CHAMBER_ANGLES
    for refinement in range(CHAMBER_REFINEMENTS + 1):
        rings = chamber_rings(data, q_values, spacing)
        vertices, faces = chamber_mesh(data, 1.0, rings, angles)
        fine, _ = chamber_mesh(data, 1.0, (rings - 1) * fine_factor + 1, angles * fine_factor)
        error = max_distance_to_mesh(fine, vertices, faces)
        if error <= tolerance_mm or refinement == CHAMBER_REFINEMENTS:
            break
        spacing, angles = spacing / 2, angles * 2
    return rings, angles, error


@dataclass(frozen=True)
class ChamberFrames:
    """The chamber's trace at every frame's q (empty where it cannot be built), its faces and notes on it."""

    frames: list[dict[str, Any]]
    faces: np.ndarray
    notes: list[str]


def chamber_frames(data: BuildData, q_values: FloatArray, fine_factor: int, tolerance_mm: float
                   ) -> ChamberFrames | None:
    """The chamber at every q of ``q_values`` as plotly trace dicts; None for a solid body or a build without fit.

    Where the chamber cannot be built (the export would refuse that q), the frame's vertices are all NaN, which
    plotly does not draw.
    """
    if data.fit is None or body_spec(data).wall_mm <= 0:
        return None
    try:
        rings, angles, error = display_chamber(data, q_values, tolerance_mm, fine_factor)
    except MeshError as err:
        return ChamberFrames([], np.zeros((0, 3), np.int64), [f"chamber: not drawn ({err})"])
    frames: list[dict[str, Any]] = []
    missing: list[str] = []
    faces = np.zeros((0, 3), np.int64)
    for q in q_values:
        try:
            vertices, faces = chamber_mesh(data, float(q), rings, angles)
        except MeshError:
            vertices = np.full((rings * angles + 2, 3), np.nan)
            missing.append(f"{q:.2f}")
        v = vertices.astype(np.float32)
        frames.append({"x": v[:, 0], "y": v[:, 1], "z": v[:, 2], "type": "mesh3d"})
    notes = [f"chamber: {rings} rings, {angles} vertices around; display error at q = 1 {error:.3f} mm (against "
             f"{fine_factor}x finer; tolerance {tolerance_mm:g} mm)"]
    if missing:
        notes.append(f"chamber: not drawn at q = {', '.join(missing)} (a wall the radius cannot take, or a fold)")
    return ChamberFrames(frames, faces, notes)


def chamber_trace(chamber: ChamberFrames) -> dict[str, Any]:
    """The hidden chamber trace the page opens on (the last frame's, q = 1), a plotly mesh3d trace dict."""
    first, f = chamber.frames[-1], chamber.faces
    return {"color": CHAMBER_RGB, "hoverinfo": "name", "i": f[:, 0], "j": f[:, 1], "k": f[:, 2],
            "name": CHAMBER_NAME, "showlegend": True, "visible": "legendonly", **{k: first[k] for k in "xyz"},
            "type": "mesh3d"}


def hidden_parts_note(data: BuildData) -> str:
    """The sentence telling the reader how to show the mould and the chamber ('' when the build has neither)."""
    parts = (["the casting mould (where it is cast, around the q = 0 body)"] if mould_block(data) else []) + (
        ["the chamber"] if data.fit is not None and body_spec(data).wall_mm > 0 else [])
    if not parts:
        return ""
    return f"Hidden at first, click the legend to show: {' and '.join(parts)}. "
