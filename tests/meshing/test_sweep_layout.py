"""Chamber and feed circles' nodes from the element size, and the cavity's area they keep (issue 32)."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.meshing.volume_mesh.sweep_layout import MIN_CHAMBER_NODES, MIN_FEED_NODES, circle_nodes


@pytest.mark.parametrize(("diameter", "size", "least", "expected"), [
    (10.0, 1.0, MIN_CHAMBER_NODES, 32),   # pi * 10 / 1 = 31.4 -> 32
    (10.0, 0.5, MIN_CHAMBER_NODES, 63),   # 62.8 -> 63
    (10.0, 4.0, MIN_CHAMBER_NODES, 16),   # 7.9 -> the floor
    (1.0, 0.1, MIN_FEED_NODES, 32),
    (1.0, 2.0, MIN_FEED_NODES, 12),
])
def test_nodes_follow_the_circumference_over_size(diameter, size, least, expected):
    assert circle_nodes(diameter, size, least) == expected


@pytest.mark.parametrize("nodes", [MIN_FEED_NODES, MIN_CHAMBER_NODES, 40])
def test_equal_area_polygon_keeps_the_cavity_area(nodes):
    """At the floors the polygon's area is the circle's within 1 % (an inscribed one loses 1 - sin h / h)."""
    radius = 0.3
    circle = Circle((0.1, 0.0), radius, nodes, equal_area=True)
    r = circle.node_radius(nodes)
    h = 2.0 * np.pi / nodes
    polygon = 0.5 * nodes * r * r * np.sin(h)
    assert polygon == pytest.approx(np.pi * radius**2, rel=0.01)
    inscribed = 0.5 * nodes * radius**2 * np.sin(h)
    assert 1.0 - inscribed / (np.pi * radius**2) == pytest.approx(1.0 - np.sin(h) / h, rel=1e-12)
