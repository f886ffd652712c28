"""softdesign check on metrics.feasibility: within tolerance, beyond it, and a reference that predates it."""

from __future__ import annotations

import copy

from softdesign.regression.feasibility import STRETCH_TOL, compare_feasibility

DISTANCE_MM = 0.01


def _manifest(stretch_max=1.3, wall=0.9, feasible=False) -> dict:
    row = {"q": 1.0, "stretch_max": stretch_max, "stretch_min": 0.7, "rho_kappa_max": 0.3, "wall_min_mm": wall}
    morph = {"stretch_max": {"value": stretch_max}, "stretch_min": {"value": 0.66}}
    return {"metrics": {"feasibility": {"per_q": [row], "morph": morph, "feasible": feasible}}}


def test_the_same_figures_pass_and_every_one_is_compared():
    notes: list[str] = []
    figures = compare_feasibility(_manifest(), copy.deepcopy(_manifest()), DISTANCE_MM, notes)
    assert all(f.passed for f in figures)
    expected = {"q=1.000 stretch_max", "q=1.000 wall_min_mm", "morph stretch_min", "feasible"}
    assert {f.figure for f in figures} >= expected


def test_a_stretch_or_wall_beyond_tolerance_or_another_verdict_fails():
    for build in (_manifest(stretch_max=1.3 + 2 * STRETCH_TOL), _manifest(wall=0.9 + 2 * DISTANCE_MM),
                  _manifest(feasible=True)):
        failed = [f.figure for f in compare_feasibility(build, _manifest(), DISTANCE_MM, []) if not f.passed]
        assert failed, build
    within = compare_feasibility(_manifest(stretch_max=1.3 + 0.5 * STRETCH_TOL), _manifest(), DISTANCE_MM, [])
    assert all(f.passed for f in within)


def test_a_reference_without_the_block_is_a_note_and_a_build_without_it_fails():
    notes: list[str] = []
    assert compare_feasibility(_manifest(), {"metrics": {}}, DISTANCE_MM, notes) == []
    assert notes and "not compared" in notes[0]
    missing = compare_feasibility({"metrics": {}}, _manifest(), DISTANCE_MM, [])
    assert len(missing) == 1 and not missing[0].passed
