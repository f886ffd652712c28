"""Figure: the radius profile along the centerline at q = 0 and q = 1, and cross-sections of the body (issue 17, 3).

Left: rho(q, l, a) from the kept radius field, its mean over a (line) and its
smallest to largest over a (band), against arc length at that q (mm); a hollow
body adds its chamber's mean radius, rho - wall_mm (dashed; the export's
chamber is the inward offset of the outer surface by ``export.wall_mm``).
Right: the exported q = 1 mesh cut by the plane normal to the centerline at a
few l (trimesh's plane section), drawn in the centerline frame's (N, B) axes:
a solid body shows one outline, a hollow one its wall and chamber, and the cut
next to the base shows the port when there is one.
"""

from __future__ import annotations

import numpy as np

from softdesign.io.surface import read_surface
from softdesign.report.build_folder import BuildData
from softdesign.report.plotting import Picture, fixed_figure, link_colours, picture, styled
from softdesign.types import FloatArray

NAME = "profile.png"
SIZE_IN = (13.0, 4.4)
#: Fixed layout of the profile and the cuts, inches: margins (left, right, bottom, top) and the gap between panels.
MARGINS_IN, GAP_IN = (0.7, 0.2, 0.5, 0.3), 0.75
#: Where the q = 1 body is cut, as distances from the base in mm (the first, near the base cap, crosses a port)
#: and fractions of the length.
SECTION_BASE_MM = 1.0
SECTION_L = (0.5, 0.9)
PROFILE_SAMPLES, PROFILE_ANGLES = 400, 96


def radius_profile(data: BuildData, q: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Arc length at q (p,) mm, and the mean, smallest and largest rho over a (p,) mm."""
    assert data.fit is not None
    curve = data.kinematics.chain.shape.curve_at(q)
    l = np.linspace(0.0, 1.0, PROFILE_SAMPLES)
    rho = data.fit.field.evaluate_grid(q, l, np.linspace(0.0, 2.0 * np.pi, PROFILE_ANGLES, endpoint=False))
    return curve.curve.arc_length(l), rho.mean(axis=1), rho.min(axis=1), rho.max(axis=1)


def cross_section(data: BuildData, vertices: FloatArray, faces: np.ndarray, l: float) -> FloatArray:
    """Segments (k, 2, 2) in mm of the mesh cut by the plane normal to the q = 1 centerline at l, in (N, B)."""
    import trimesh

    curve = data.kinematics.chain.shape.curve_at(1.0)
    origin, frame = curve.points([l])[0], curve.frames([l])[0]
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    segments = trimesh.intersections.mesh_plane(mesh, plane_normal=frame[:, 2], plane_origin=origin)
    return np.asarray((np.asarray(segments).reshape(-1, 3) - origin) @ frame[:, :2]).reshape(-1, 2, 2)


def profile_picture(data: BuildData) -> Picture | None:
    """The figure, or None when the build has no fit."""
    if data.fit is None:
        return None
    from matplotlib.collections import LineCollection

    wall = float(data.manifest.get("case", {}).get("export", {}).get("wall_mm") or 0.0)
    mesh_file = data.mesh_file(1.0)
    length = data.kinematics.chain.shape.curve_at(1.0).length
    cuts = [min(SECTION_BASE_MM / length, 0.5), *SECTION_L]
    with styled():
        figure = fixed_figure(SIZE_IN, MARGINS_IN, (GAP_IN, 0.0), (1, 1 + len(cuts)))
        grid = figure.add_gridspec(1, 1 + len(cuts), width_ratios=[2.2] + [1.0] * len(cuts))
        ax = figure.add_subplot(grid[0, 0])
        for q, colour, style in ((1.0, "#d62728", "-"), (0.0, "#1f77b4", ":")):  # q = 0 on top: often the same mean
            s, mean, low, high = radius_profile(data, q)
            ax.fill_between(s, low, high, color=colour, alpha=0.2, linewidth=0, label=f"q = {q:g}: smallest to largest")
            ax.plot(s, mean, color=colour, lw=1.8, ls=style, label=f"q = {q:g}: mean over the angle")
            if wall > 0:
                ax.plot(s, mean - wall, color=colour, lw=1.0, ls="--", label=f"q = {q:g}: chamber (mean - wall)")
        ax.set(xlabel="arc length along the centerline at that q (mm)", ylabel="radius rho (mm)",
               title="radius profile", ylim=(0.0, None))
        ax.legend(loc="best", fontsize=7)
        mesh = read_surface(mesh_file) if mesh_file is not None else None
        colours = link_colours(data.link_count)
        for k, l in enumerate(cuts):
            cut_ax = figure.add_subplot(grid[0, k + 1])
            cut_ax.set(aspect="equal", xlabel="N (mm)", ylabel="B (mm)" if k == 0 else "")
            if mesh is None:
                cut_ax.axis("off")
                cut_ax.text(0.5, 0.5, "no q = 1 mesh exported", ha="center", transform=cut_ax.transAxes)
                continue
            segments = cross_section(data, *mesh, l)
            link = int(data.fit.field.link_of(np.array([l]))[0])
            cut_ax.add_collection(LineCollection(list(segments), colors=[colours[link]], linewidths=1.2,
                                                 label=f"mesh at q = 1 (link {link})"))
            cut_ax.autoscale_view()
            cut_ax.set_title(f"cut at {l * length:.1f} mm (l = {l:.3f})")
            cut_ax.legend(loc="lower center", fontsize=6.5)
    caption = (
        "Left: the fitted radius rho(l, a) along the centerline at q = 0 and q = 1, its mean over the angle and its "
        "range (band)" + (", and the chamber's mean radius for this hollow body" if wall > 0 else "") + ". Right: "
        "the exported q = 1 mesh cut by planes normal to the centerline (near the base, half way, 90 %), in the "
        "local (N, B) axes: a hollow body shows its wall and chamber, the cut by the base its port."
    )
    return picture(NAME, figure, SIZE_IN, "Radius profile and cross-sections", caption)
