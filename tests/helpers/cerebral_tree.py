"""A cerebral-like tree: a trunk with short terminal branches, capped flat, of known openings (issue 43, item 4).

A trunk of radius 1.5 mm runs 25 mm along +z; six branches of radius 0.5 to 0.8 mm leave it every 3.2 mm,
60 to 80 degrees from the trunk, turning 2.3 x 60 degrees around it from one to the next, each ending two
diameters past the trunk's wall: short terminal branches, as a cerebral tree's perforators are.  The wall
is the manifold3d union of the capped cylinders; every opening is a flat cap of known centre and radius.
"""

from __future__ import annotations

import numpy as np

TRUNK_RADIUS_MM = 1.5
TRUNK_LENGTH_MM = 25.0
BRANCHES = 6


def cerebral_tree(edge_mm: float = 0.15) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (V, 3) mm, faces (F, 3), and each opening's centre (k, 3) mm and radius (k,) mm."""
    import manifold3d

    def segments(radius: float) -> int:
        return int(np.ceil(2 * np.pi * radius / edge_mm))

    body = manifold3d.Manifold.cylinder(TRUNK_LENGTH_MM, TRUNK_RADIUS_MM, TRUNK_RADIUS_MM,
                                        segments(TRUNK_RADIUS_MM))
    centres = [np.zeros(3), np.array([0.0, 0.0, TRUNK_LENGTH_MM])]
    radii = [TRUNK_RADIUS_MM, TRUNK_RADIUS_MM]
    for k in range(BRANCHES):
        z, azimuth = 4.0 + 3.2 * k, 2 * np.pi * k / BRANCHES * 2.3
        radius, tilt = 0.5 + 0.15 * (k % 3), np.radians(60 + 10 * (k % 3))
        direction = np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)])
        length = TRUNK_RADIUS_MM + 4.0 * radius  # two diameters past the trunk's wall
        branch = manifold3d.Manifold.cylinder(length, radius, radius, segments(radius))
        body += branch.rotate((0.0, float(np.degrees(tilt)), 0.0)).rotate((0.0, 0.0, float(np.degrees(azimuth))))\
            .translate((0.0, 0.0, z))
        centres.append(np.array([0.0, 0.0, z]) + length * direction)
        radii.append(radius)
    mesh = body.refine_to_length(edge_mm).to_mesh()
    return (np.asarray(mesh.vert_properties[:, :3], float), np.asarray(mesh.tri_verts, np.int64), np.array(centres),
            np.array(radii))
