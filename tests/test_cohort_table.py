"""The cohort table: one row per case with the skin's stretch, the thinnest wall, the verdict, the design's
deviation, one mesh per q; an older, different table is kept, never silently overwritten (issue 34)."""

from __future__ import annotations

import csv
import io
import json

from softdesign import cohort


def _build_folder(folder, feasible, formats=("stl", "ply", "obj"), design=None):
    folder.mkdir()
    outputs = [{"path": f"meshes/q_{q}.{fmt}", "volume_mm3": 100.0 + i, "watertight": True}
               for i, q in enumerate(("0.000", "0.500", "1.000")) for fmt in formats]
    outputs.append({"path": "meshes/mould/half_a.stl", "volume_mm3": 5000.0, "watertight": True})
    metrics = {
        "fit": {"rms_mm": 0.05},
        "kinematics": {"links": 3},
        "blend": {"per_q": [{"stretch_min": 0.96, "stretch_max": 1.0001}]},
        "feasibility": {
            "feasible": feasible,
            "per_q": [{"q": 0.0, "wall_min_mm": 1.4}, {"q": 1.0, "wall_min_mm": 0.9}],
            "morph": {"stretch_min": {"value": 0.505}, "stretch_max": {"value": 1.588}},
        },
    }
    if design is not None:
        metrics["design"] = design
    manifest = {"metrics": metrics, "outputs": outputs, "case": {"export": {"wall_mm": 1.5}}}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder


def test_the_row_shows_the_skin_and_the_verdict_not_the_centerlines_stretch(tmp_path):
    figures = cohort.manifest_figures(_build_folder(tmp_path / "aorta", False))
    assert figures["feasible"] == "false"
    assert (figures["skin_stretch_min"], figures["skin_stretch_max"]) == (0.505, 1.588)
    assert (figures["axial_stretch_min"], figures["axial_stretch_max"]) == (0.96, 1.0001)
    assert figures["wall_min_mm"] == 0.9
    # three formats of three q: three meshes, one volume each (the mould's parts are not body meshes)
    assert figures["meshes"] == 3
    assert figures["volumes_mm3"] == "q_0.000=100 q_0.500=101 q_1.000=102"
    assert figures["chain_deviation_mm"] == "" and figures["tip_error_mm"] == ""


def test_the_row_gives_the_designs_deviation_and_a_not_judged_verdict(tmp_path):
    design = {"chain_max_deviation_mm": 0.8, "tip_error_mm": 0.33}
    figures = cohort.manifest_figures(_build_folder(tmp_path / "demo", None, ("stl",), design))
    assert figures["feasible"] == "not judged"
    assert (figures["chain_deviation_mm"], figures["tip_error_mm"]) == (0.8, 0.33)


def test_the_rows_verdict_is_the_builds_one_when_the_manifest_records_it(tmp_path):
    """Issue 44: the chambers' walls can make a design infeasible whose skin passes: the row says what the
    terminal and the report say."""
    folder = _build_folder(tmp_path / "actuator", True)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["verdict"] = {"feasible": False, "status": "NOT feasible", "reasons": ["chambers: wall 0.4 mm < 1"]}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    assert cohort.manifest_figures(folder)["feasible"] == "false"


def test_a_different_older_table_is_kept_and_the_same_one_is_not_duplicated(tmp_path):
    table = tmp_path / "cohort-summary.csv"
    row = {column: "" for column in cohort.SUMMARY_COLUMNS} | {"case": "a", "status": "ok"}
    assert cohort.write_summary_csv([row], table) is None
    assert cohort.write_summary_csv([row], table) is None  # the same table: nothing kept twice
    first = table.read_text()
    changed = row | {"status": "failed"}
    kept = cohort.write_summary_csv([changed], table)
    assert kept == tmp_path / "cohort-summary.1.csv" and kept.read_text() == first
    assert next(csv.DictReader(io.StringIO(table.read_text())))["status"] == "failed"
    kept_again = cohort.write_summary_csv([row], table)
    assert kept_again == tmp_path / "cohort-summary.2.csv"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cohort-summary.1.csv", "cohort-summary.2.csv",
                                                          "cohort-summary.csv"]
