"""Issue 36 item 13: ``softdesign centerline`` refuses results that cannot be a vessel's axis, with the evidence.

Before, each of these exited 0 and wrote a file: a closed sphere (a 0.16 mm
line), a coarse capped cylinder of radius 3 (radius 20 to 30), a thick-walled
tube (no line), a surface scaled by 1e-6 (a 0.00 mm line).  Each runs in a
child (stderr apart): exit 2, the evidence named, no file written, and no
Python warning on stderr.
"""

from __future__ import annotations

import pytest

from tests.helpers.attacks import assert_refused, run_limited


def _sphere(path):
    import trimesh

    trimesh.creation.icosphere(subdivisions=3, radius=10.0).export(path)


def _coarse_cylinder(path):
    import trimesh

    trimesh.creation.cylinder(radius=3.0, height=40.0, sections=8).export(path)


def _tiny_cylinder(path):
    import trimesh

    tube = trimesh.creation.cylinder(radius=3.0, height=40.0, sections=48)
    tube.apply_scale(1e-6)
    tube.export(path)


def _thick_tube(path):
    import trimesh

    trimesh.creation.annulus(r_min=3.0, r_max=6.0, height=40.0, sections=48).export(path)


@pytest.mark.parametrize(
    ("make", "needles"),
    [
        (_sphere, ["no opening", "mm long but"]),
        (_coarse_cylinder, ["mm from the wall", "cannot reach through the wall"]),
        (_tiny_cylinder, ["mm across", "--units"]),
        (_thick_tube, ["cannot reach through the wall"]),
    ],
    ids=["closed-sphere", "coarse-cylinder", "scaled-1e-6", "thick-walled-tube"],
)
def test_meaningless_centerlines_are_refused_with_the_evidence(tmp_path, make, needles):
    surface = tmp_path / "surface.stl"
    make(surface)
    output = tmp_path / "centerline.vtp"
    result = run_limited("centerline", str(surface), "--output", str(output))
    assert_refused(result, *needles)
    assert not output.exists()
    assert "Warning" not in result.stderr, result.stderr
