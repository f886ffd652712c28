"""Figure 2, the surfaces: the input vessel beside the actuator at q = 0, an intermediate q and q = 1.

Every panel is a shaded projection (painter's algorithm, two-sided Lambert
shading) seen along the final centerline's direction of least spread, so the
patient's shape shows its broadest side.  The actuator is the exported STL
when that q was exported, else the open tube S(q, l, a) tessellated from the
radius field (the caption says which).  A vessel of more than
``VESSEL_FACES`` triangles is shown decimated as the 3D view shows it, within
its display tolerance (:mod:`softdesign.report.display_mesh`; the caption gives
the measured error).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.fitting.radius_field import RadiusField
from softdesign.io.surface import read_surface
from softdesign.kinematics.links import LinkChain
from softdesign.report.build_folder import BuildData
from softdesign.report.display_mesh import DISPLAY_TOLERANCE_MM
from softdesign.report.plotting import Picture, fixed_figure, picture, styled
from softdesign.report.projection import View, principal_view, shaded_triangles
from softdesign.types import FloatArray

SIZE_IN = (12.0, 7.0)
#: Fixed layout of the 2 x 2 views, inches: margins (left, right, bottom, top) and gaps (columns, rows),
#: room for tick labels up to 6 characters wide, the axis labels and one line of title.
MARGINS_IN, GAPS_IN = (0.7, 0.2, 0.45, 0.3), (0.8, 0.75)
#: Tube tessellation when a q has no exported mesh: spacing along the centerline (mm) and angles around.
TUBE_SPACING_MM = 0.5
TUBE_ANGLES = 48
#: Samples of the final centerline whose direction of least spread every shaded figure looks along.
VIEW_SAMPLES = 101
#: Base colours (RGB), scaled by the brightness: the patient's vessel and the actuator.
VESSEL_RGB = (0.86, 0.42, 0.38)
ACTUATOR_RGB = (0.45, 0.62, 0.85)


@dataclass(frozen=True)
class Body:
    """One panel's mesh: vertices (V, 3) mm, faces (F, 3) and where it came from."""

    title: str
    vertices: FloatArray
    faces: np.ndarray
    source: str
    rgb: tuple[float, float, float] = ACTUATOR_RGB
    closed: bool = False  #: a checked, outward-wound solid: faces turned away are hidden and need not be drawn


def final_view(chain: LinkChain) -> View:
    """The view of every shaded figure: along the final (q = 1) centerline's direction of least spread, inlet first."""
    samples = chain.shape.curve_at(1.0).points(np.linspace(0.0, 1.0, VIEW_SAMPLES))
    return principal_view(samples, samples[-1] - samples[0])


def intermediate_q(q_values: list[float]) -> float:
    """The export q strictly between 0 and 1 nearest 0.5, else 0.5."""
    inside = [q for q in q_values if 0.0 < q < 1.0]
    return min(inside, key=lambda q: (abs(q - 0.5), q)) if inside else 0.5


def tube_mesh(
    chain: LinkChain, field: RadiusField, q: float, spacing_mm: float = TUBE_SPACING_MM, angles: int = TUBE_ANGLES,
    rings: int | None = None,
) -> tuple[FloatArray, np.ndarray, FloatArray]:
    """The open tube c(q, l) + rho(q, l, a) (cos a N + sin a B) on a regular (l, a) grid.

    ``rings``: the number of rings (else rings about ``spacing_mm`` apart at this q): the same at every q gives
    the same faces at every q.

    Returns
    -------
    vertices (V, 3) mm, faces (F, 3) int64 (two per grid cell) and the l (F,) at which each face starts.
    """
    curve = chain.shape.curve_at(q)
    count = rings if rings is not None else max(int(np.ceil(curve.length / spacing_mm)), 8) + 1
    l = np.linspace(0.0, 1.0, count)
    a = np.linspace(0.0, 2.0 * np.pi, angles, endpoint=False)
    frames, centre = curve.frames(l), curve.points(l)
    rho = field.evaluate_grid(q, l, a)  # (count, angles)
    direction = np.cos(a)[None, :, None] * frames[:, None, :, 0] + np.sin(a)[None, :, None] * frames[:, None, :, 1]
    vertices = (centre[:, None, :] + rho[:, :, None] * direction).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(count - 1), np.arange(angles), indexing="ij")
    p00, p01 = i * angles + k, i * angles + (k + 1) % angles
    p10, p11 = p00 + angles, p01 + angles
    # counter-clockwise seen from outside, as every mesh of the package
    faces = np.concatenate([np.stack([p00, p11, p10], -1).reshape(-1, 3), np.stack([p00, p01, p11], -1).reshape(-1, 3)])
    return vertices, faces.astype(np.int64), np.tile(l[i.ravel()], 2)


def actuator_body(data: BuildData, q: float) -> Body | None:
    """The exported mesh at q, else the tessellated tube, else None (no fit in the build)."""
    file = data.mesh_file(q)
    if file is not None:
        vertices, faces = read_surface(file)
        return Body(f"actuator, q = {q:g}", vertices, faces, f"{file.parent.name}/{file.name}", closed=True)
    if data.fit is None:
        return None
    vertices, faces, _ = tube_mesh(data.kinematics.chain, data.fit.field, q)
    return Body(f"actuator, q = {q:g}", vertices, faces, "tube tessellated from the radius field (q not exported)")


def draw_shaded(ax, body: Body, view: View) -> None:
    """One shaded body on a 2-D axes with equal scale."""
    from softdesign.report.flat_triangles import add_triangles

    triangles, brightness, _ = shaded_triangles(body.vertices, body.faces, view, cull=body.closed)
    add_triangles(ax, triangles, np.clip(brightness[:, None] * np.asarray(body.rgb)[None, :], 0.0, 1.0))
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_title(body.title)
    ax.set_xlabel(view.labels[0])
    ax.set_ylabel(view.labels[1])


def surface_bodies(data: BuildData) -> list[Body]:
    """The input surface (when the build has one) and the actuator at 0, an intermediate q and 1."""
    bodies = []
    if len(data.ingest.faces):
        name = data.manifest.get("metrics", {}).get("ingest", {}).get("surface", {}) or {}
        vertices, faces, error = data.vessel_display
        source = name.get("file", "input")
        if len(faces) < len(data.ingest.faces):
            source += (f" (shown decimated: {len(faces)} of {len(data.ingest.faces)} triangles, display error "
                       f"{error:.3f} mm, tolerance {DISPLAY_TOLERANCE_MM:g} mm)")
        bodies.append(Body("input vessel surface", vertices, faces, source, VESSEL_RGB))
    for q in (0.0, intermediate_q(data.export_q), 1.0):
        body = actuator_body(data, q)
        if body is not None:
            bodies.append(body)
    return bodies


def surface_picture(data: BuildData) -> Picture | None:
    """Figure 2 as a PNG, or None when the build has no fit (nothing to draw but the input)."""
    if data.fit is None:
        return None
    bodies = surface_bodies(data)
    view = final_view(data.kinematics.chain)
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, GAPS_IN, (2, 2))
        for k, body in enumerate(bodies):
            draw_shaded(figure.add_subplot(2, 2, k + 1), body, view)
    sources = "; ".join(f"{b.title}: {b.source}" for b in bodies)
    caption = (
        "Shaded views, all along the same direction (the final centerline's direction of least spread; "
        f"screen right runs from inlet to outlet). Sources: {sources}."
    )
    return picture("surfaces.png", figure, SIZE_IN, "The surface at q = 0, in between and at q = 1", caption)
