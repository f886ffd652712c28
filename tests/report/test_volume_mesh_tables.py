"""The report's volume mesh table and checks, from a summary as the stage writes it."""

from __future__ import annotations

from softdesign.report.volume_mesh_tables import volume_mesh_checks, volume_mesh_table


def row(**changes):
    figures = {"q": 0.0, "tets": 15157, "volume_rel_error": -0.00293, "volume_rtol": 0.01,
               "chamber_centroids_inside": 0, "min_dihedral_deg": 12.56, "max_dihedral_deg": 153.8,
               "max_radius_edge": 2.96, "size_mm": 2.0, "mean_edge_mm": 1.19,
               "min_tet_volume_mm3": 0.0058}
    return {**figures, **changes}


def test_nothing_without_a_volume_mesh():
    assert volume_mesh_table(None) is None and volume_mesh_checks({"requested": False}) == []


def test_table_and_checks_of_a_hollow_body():
    summary = {"requested": True, "per_q": [row()]}
    table = volume_mesh_table(summary)
    assert table is not None and len(table.rows) == 1
    assert [c.text for c in table.rows[0]][:4] == ["0.000", "15157", "-0.293 %", "0"]
    checks = volume_mesh_checks(summary)
    assert [c.name for c in checks] == ["every tetrahedron positive", "volume vs body", "tetrahedra in the chamber"]
    assert all(c.passed for c in checks)


def test_failed_figures_fail_their_checks_and_a_solid_has_no_chamber_check():
    checks = volume_mesh_checks({"requested": True, "per_q": [
        row(volume_rel_error=0.02, chamber_centroids_inside=None, min_tet_volume_mm3=-1.0)]})
    assert [c.passed for c in checks] == [False, False]


def test_a_swept_mesh_shows_its_3d_stretch_and_stress():
    strain = {"stretch_max": {"value": 1.3461}, "stress_max_kpa": {"value": 32.7}}
    summary = {"requested": True, "deterministic": True,
               "per_q": [row(chamber_centroids_inside=None, mean_edge_mm=None, strain=strain)]}
    table = volume_mesh_table(summary)
    assert table is not None and "swept" in table.caption
    cells = [c.text for c in table.rows[0]]
    assert cells[3] == "-" and cells[7] == "2 / -" and cells[8:10] == ["1.3461", "32.7 kPa"]
