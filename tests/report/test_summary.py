"""The summary's warnings and the checks' order, from hand-made manifests (no build)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from softdesign.report import display_mesh
from softdesign.report.display_mesh import decimated_vessel
from softdesign.report.html_page import banner_html, compact_check_tables
from softdesign.report.summary import summary_warnings
from softdesign.report.tables import Check


def test_the_banner_lists_the_manifests_warnings_each_once_and_its_notes_apart():
    manifest = {"warnings": [
        {"stage": "ingest", "code": "note", "place": "", "text": "3 duplicate points removed", "kind": "note"},
        {"stage": "kinematics", "code": "arc_misfit", "place": "link 0", "text": "link 0: 1.9 mm from its arc",
         "kind": "warning"},
        {"stage": "export", "code": "stale", "place": "", "text": "out of date", "kind": "warning"}]}
    warnings, notes = summary_warnings(manifest)
    assert warnings == ["kinematics: link 0: 1.9 mm from its arc", "export: out of date"]
    assert notes == ["ingest: 3 duplicate points removed"]
    page = banner_html(warnings, notes)
    assert page.count("<li>") == 3 and 'role="alert"' in page and "No warnings" not in page


def test_a_build_without_warnings_says_so_and_only_then():
    assert summary_warnings({"warnings": []}) == ([], [])
    assert 'class="allclear"' in banner_html([]) and "No warnings." in banner_html([])


def test_failures_first_then_a_tally_per_kind_and_every_passed_check_folded():
    checks = [Check("a.stl", "file as recorded (sha256)", "matches", "x", True),
              Check("a.stl", "watertight", "yes", "yes", True),
              Check("b.stl", "file as recorded (sha256)", "differs", "x", False),
              Check("b.stl", "watertight", "no", "yes", False),
              Check("c.stl", "watertight", "yes", "yes", True)]
    failed, tally, folded = compact_check_tables(checks)
    assert [(r[0].text, r[1].text) for r in failed.rows] == [("b.stl", "file as recorded (sha256)"),
                                                               ("b.stl", "watertight")]
    assert [tuple(c.text for c in r) for r in tally.rows] == [("file as recorded (sha256)", "1", "2", "some failed"),
                                                               ("watertight", "2", "3", "some failed")]
    assert [(r[0].text, r[1].text) for r in folded.rows] == [("a.stl", "file as recorded (sha256)"),
                                                               ("a.stl", "watertight"), ("c.stl", "watertight")]
    assert folded.folded and not failed.folded and tally.caption == "Checks: 3 of 5 passed"
    assert len(compact_check_tables(checks[:2])) == 2  # no failure: no failures table


#: Display tolerance for a decimated 10 mm sphere: 1 % of its radius.
SPHERE_DISPLAY_MM = 0.1


def test_the_vessel_is_decimated_for_display_within_a_measured_error():
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=10.0)  # 20480 faces
    vertices, faces, error = decimated_vessel(np.asarray(sphere.vertices), np.asarray(sphere.faces), target=2000)
    assert len(faces) <= 2000
    # every decimated vertex is one of the sphere's kept or moved ones: close to the sphere
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), 10.0, rtol=0, atol=SPHERE_DISPLAY_MM)
    # chords of ~2000 triangles on R = 10 mm sag by about 0.05 mm: the measured error is that, not 0
    assert 0.0 < error < SPHERE_DISPLAY_MM
    kept_v, kept_f, none = decimated_vessel(np.asarray(sphere.vertices), np.asarray(sphere.faces), target=30000)
    assert none == 0.0 and len(kept_f) == 20480


def test_a_vessel_decimated_past_the_tolerance_keeps_more_triangles_until_within_it():
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=10.0)  # 20480 faces
    vertices, faces = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    _, coarse, coarse_error = decimated_vessel(vertices, faces, target=500, tolerance_mm=1.0)
    tolerance = 0.5 * coarse_error  # the 500-face decimation misses it: the target must grow
    _, kept, error = decimated_vessel(vertices, faces, target=500, tolerance_mm=tolerance)
    assert len(coarse) <= 500 < len(kept) and error <= tolerance


@pytest.mark.slow
def test_a_large_vessel_is_clustered_first_then_decimated_within_the_tolerance(monkeypatch):
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=10.0)  # 81920 faces: over 8 x the target
    vertices, faces = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    shown_v, shown_f, error = display_mesh.decimated_surface(vertices, faces, target=2000, tolerance_mm=0.2)
    assert len(shown_f) <= 2000 and 0.0 < error <= 0.2
    assert error == pytest.approx(display_mesh.max_distance_to_mesh(vertices, shown_v, shown_f), abs=1e-12)
    cells = []
    real = display_mesh.clustered

    def counted(v, f, cell_mm):
        cells.append(cell_mm)
        return real(v, f, cell_mm)

    monkeypatch.setattr(display_mesh, "clustered", counted)
    display_mesh.decimated_surface(vertices, faces, target=2000, tolerance_mm=0.2)
    assert cells == [display_mesh.CLUSTER_CELL_FRACTION * 0.2]
    # a grid of 8 cells over the sphere's box strays far past the tolerance: the original is decimated instead
    monkeypatch.setattr(display_mesh, "MAX_CLUSTER_BINS", 8)
    coarse_v, coarse_f = real(vertices, faces, 0.1)
    assert display_mesh.max_distance_to_mesh(vertices, coarse_v, coarse_f) > 0.2
    _, kept, error = display_mesh.decimated_surface(vertices, faces, target=2000, tolerance_mm=0.2)
    assert len(kept) <= 2000 and error <= 0.2


def test_the_largest_display_error_measured_by_bound_is_the_largest_over_every_point():
    from softdesign.meshing.compare import squared_distances

    # a lumpy sphere's 40962 vertices (over EXACT_POINTS: measured by bound), a few of them pushed off the surface,
    # against its decimations to a few hundred and a few thousand faces, and against a mesh with a degenerate face
    rng = np.random.default_rng(8)
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=10.0)
    vertices = np.asarray(sphere.vertices) * rng.uniform(0.98, 1.02, (len(sphere.vertices), 1))
    vertices[rng.choice(len(vertices), 5, replace=False)] *= 1.3
    faces = np.asarray(sphere.faces)
    assert len(vertices) > display_mesh.EXACT_POINTS
    for target in (300, 3000):
        shown_v, shown_f = display_mesh._quadric_decimation(vertices, faces, target)
        shown_f = np.concatenate([shown_f, [[0, 0, 1]]])  # a sliver: its bound is a vertex's distance
        every = float(np.sqrt(squared_distances(vertices, shown_v, shown_f).max()))
        assert display_mesh.max_distance_to_mesh(vertices, shown_v, shown_f) == every
        bounds = display_mesh.distance_bounds(vertices, shown_v, shown_f)
        assert np.all(bounds ** 2 >= squared_distances(vertices, shown_v, shown_f))
