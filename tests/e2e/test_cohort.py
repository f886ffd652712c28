"""The sample cohort's generator, the cohort helpers, and `make cohort` on a two-case temporary cohort."""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from softdesign import cohort
from softdesign.config import load_case
from softdesign.samples.cohort_vessels import COHORT_VARIANTS, make_variant_vessel, variant_named
from tests.helpers.paths import REPO
from tests.helpers.regeneration import REGENERATION_TOL_MM, assert_same_vessel_file, vessel_file_differences

MAKE = shutil.which("make")
needs_make = pytest.mark.skipif(MAKE is None, reason="GNU make not found (the cohort is a make recipe)")
#: The two quickest sample cases make the temporary cohort.
MAKE_CASES = ("meander", "s_bend")


# --- the generator and the committed sample cohort ---------------------------------


def test_committed_cohort_inputs_are_the_generators_output(tmp_path):
    """data/cohort is what `make cohort-sample` writes, within REGENERATION_TOL_MM (so it never goes stale)."""
    from softdesign.samples.files import COHORT_FILE_UNITS, write_cohort
    from softdesign.types import UNIT_SCALE_TO_MM

    written = write_cohort(tmp_path)
    assert len(written) == 2 * len(COHORT_VARIANTS)
    for path in written:
        relative = path.relative_to(tmp_path)
        scale = UNIT_SCALE_TO_MM[COHORT_FILE_UNITS.get(relative.parts[0], "mm")]
        assert_same_vessel_file(path, REPO / "data" / "cohort" / relative, scale_to_mm=scale)


def test_cohort_generator_gives_the_same_bytes_twice(tmp_path):
    """Within one environment the cohort generator is byte-for-byte repeatable."""
    from softdesign.samples.files import write_cohort

    first, second = write_cohort(tmp_path / "a"), write_cohort(tmp_path / "b")
    assert [p.read_bytes() for p in first] == [p.read_bytes() for p in second]


def test_regeneration_check_sees_a_cohort_surface_moved_by_1e_6_mm(tmp_path):
    """The cohort's PLY walls store float64: a vertex moved by 1e-6 mm fails, by 1e-12 mm passes."""
    import trimesh

    from softdesign.io.formats import write_mesh

    committed = REPO / "data" / "cohort" / "arch" / "surface.ply"
    mesh = trimesh.load(committed, process=False)
    for name, move in (("moved.ply", 1e-6), ("rounded.ply", 1e-3 * REGENERATION_TOL_MM)):
        vertices = np.array(mesh.vertices)
        vertices[len(vertices) // 2, 2] += move
        write_mesh(tmp_path / name, vertices, mesh.faces)
    assert vessel_file_differences(tmp_path / "moved.ply", committed)[0].startswith("vertices: 1 of")
    assert vessel_file_differences(tmp_path / "rounded.ply", committed) == []


def test_sample_cohort_differs_in_shape_radius_and_links():
    cases = [load_case(p) for p in cohort.cohort_cases(REPO / "configs" / "cohort")]
    assert len(cases) >= 4
    paths = {variant_named(c.name).path for c in cases}
    radii = {variant_named(c.name).radius_mm[0] for c in cases}
    links = {(c.links.count, c.links.length_mm, tuple(c.links.breaks or ())) for c in cases}
    assert len(paths) == len(radii) == len(links) == len(cases)


@pytest.mark.parametrize("variant", COHORT_VARIANTS, ids=lambda v: v.name)
def test_variant_vessel_is_a_vmtk_style_network(variant):
    vessel = make_variant_vessel(variant)
    trunk = vessel.trunk_count()
    # the branch repeats the trunk's points exactly up to the junction, then leaves it
    np.testing.assert_array_equal(vessel.branch[:trunk], vessel.main[:trunk])
    assert np.linalg.norm(vessel.branch[-1] - vessel.main[trunk]) > 0.5 * variant.branch_length_mm
    step = np.linalg.norm(np.diff(vessel.main, axis=0), axis=1)
    np.testing.assert_allclose(step, variant.spacing_mm, rtol=0.02)  # resampled by arc length (chords of a curve)
    np.testing.assert_allclose(vessel.main_radius[[0, -1]], variant.radius_mm, rtol=0, atol=1e-12)


def test_helix_has_the_curvature_of_its_coil():
    """Known answer: a helix of radius a and pitch 2 pi c has curvature a / (a^2 + c^2)."""
    main = make_variant_vessel(variant_named("coil")).main
    a, c = 6.0, 24.0 / (2 * np.pi)
    first, second = np.gradient(main, axis=0), np.gradient(np.gradient(main, axis=0), axis=0)
    kappa = np.linalg.norm(np.cross(first, second), axis=1) / np.linalg.norm(first, axis=1) ** 3
    # central differences on 0.5 mm samples: O(h^2 kappa^3) error, far below 1e-3 /mm
    np.testing.assert_allclose(kappa[5:-5], a / (a**2 + c**2), rtol=0, atol=1e-3)


def test_unknown_variant_names_the_choices():
    with pytest.raises(ValueError, match="arch, coil, meander, s_bend"):
        variant_named("aorta")


# --- helpers --------------------------------------------------------------------------


def test_deps_name_the_inputs_relative_to_make_and_survive_a_bad_case(tmp_path):
    case = REPO / "configs" / "cohort" / "meander.yaml"
    text = cohort.deps_text(case, "build/meander/manifest.json", REPO)
    rule, empty = [line for line in text.splitlines() if not line.startswith("#")]
    inputs = "data/cohort/meander/centerline.vtp data/cohort/meander/surface.ply"
    assert rule == f"build/meander/manifest.json: {inputs}"
    assert empty == f"{inputs}:"  # missing inputs must not stop make: the case's build reports them
    bad = tmp_path / "bad case.yaml"
    bad.write_text("final: [not, a, mapping\n")
    assert "cannot be read" in cohort.deps_text(bad, "x", tmp_path)
    spaced = tmp_path / "in dir"
    spaced.mkdir()
    (spaced / "c.yaml").write_text("final: {centerline: a b.vtp}\n")
    assert cohort.deps_text(spaced / "c.yaml", "t", tmp_path).splitlines()[1] == "t: in\\ dir/a\\ b.vtp"


def test_error_message_takes_the_error_lines_or_the_last_line():
    log = "[ingest] running\nerror: case.yaml: the case file is invalid:\n  case.yaml:3: unknown key\nFix it.\n"
    assert cohort.error_message(log, 2) == "case.yaml: the case file is invalid: case.yaml:3: unknown key Fix it."
    assert cohort.error_message("Traceback ...\nKeyError: 'x'\n", 1) == "KeyError: 'x'"
    assert cohort.error_message("", 3) == "exited with code 3 and no output"
    assert len(cohort.error_message("error: " + "x" * 1000, 1)) == cohort.MESSAGE_CHARS


def test_run_logged_records_failure_with_its_message(tmp_path):
    command = [sys.executable, "-c", "import sys; print('working'); sys.exit('error: input.vtp: not found')"]
    record = cohort.run_logged("c", command, tmp_path / "c.log")
    assert (record.status, record.exit_code, record.message) == ("failed", 1, "input.vtp: not found")
    assert "working" in (tmp_path / "c.log").read_text()
    cohort.write_record(record, tmp_path / "c.status.json")
    assert cohort.read_record(tmp_path / "c.status.json") == record


def test_rows_of_unbuilt_and_interrupted_cases_are_not_ok(tmp_path):
    assert cohort.case_row("a", tmp_path / "a", None)["status"] == "not built"
    running = cohort.RunRecord("a", "running", None, 0.0, "", "a.log")
    row = cohort.case_row("a", tmp_path / "a", running)
    assert row["status"] == "failed" and "interrupted" in row["message"]


# --- make cohort ----------------------------------------------------------------------


def make(*args: str, cohort_dir: Path, build: Path) -> subprocess.CompletedProcess:
    """`make ARGS` in the repository on a cohort folder; the venv is never (re)installed from a test."""
    softdesign = Path(sys.executable).with_name("softdesign")
    variables = [
        f"COHORT={cohort_dir}",
        f"COHORT_BUILD={build}",
        "COHORT_NEEDS=",
        f"COHORT_PYTHON={sys.executable}",
    ] + ([f"COHORT_SOFTDESIGN={softdesign}"] if softdesign.is_file() else [])
    # under `make test`, the outer make's flags (-n, -k, -j and its jobserver) must not leak in
    env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES")}
    command = [MAKE, "-C", str(REPO), *args, *variables]
    return subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)


def temporary_cohort(root: Path, names=MAKE_CASES) -> Path:
    """Copies of sample cases and their inputs (same relative layout), so a test may touch them."""
    (root / "configs" / "cohort").mkdir(parents=True)
    for name in names:
        shutil.copy(REPO / "configs" / "cohort" / f"{name}.yaml", root / "configs" / "cohort")
        shutil.copytree(REPO / "data" / "cohort" / name, root / "data" / "cohort" / name)
    return root / "configs" / "cohort"


def summary(build: Path) -> dict[str, dict[str, str]]:
    with (build / "cohort-summary.csv").open(newline="") as handle:
        return {row["case"]: row for row in csv.DictReader(handle)}


def built(build: Path, name: str) -> int:
    return (build / name / "manifest.json").stat().st_mtime_ns


def builds_in(dry_run: str, build: Path) -> set[str]:
    """The cases a `make -n` output would build."""
    return {name for name in MAKE_CASES + ("broken", "missing") if f"--out {build}/{name}" in dry_run}


@pytest.mark.slow
@needs_make
def test_make_cohort_rebuilds_only_what_changed(tmp_path):
    cases, build = temporary_cohort(tmp_path), tmp_path / "build"
    first = make("-j2", "cohort", cohort_dir=cases, build=build)
    assert first.returncode == 0, first.stdout + first.stderr
    rows = summary(build)
    assert {name: row["status"] for name, row in rows.items()} == {name: "ok" for name in MAKE_CASES}
    assert all(float(rows[name]["fit_rms_mm"]) > 0 and int(rows[name]["meshes"]) >= 2 for name in MAKE_CASES)

    # a second make has nothing to do
    assert make("-q", "cohort", cohort_dir=cases, build=build).returncode == 0
    assert builds_in(make("-n", "cohort", cohort_dir=cases, build=build).stdout, build) == set()

    # a touched case file rebuilds that case only
    before = {name: built(build, name) for name in MAKE_CASES}
    os.utime(cases / "meander.yaml")
    assert builds_in(make("-n", "cohort", cohort_dir=cases, build=build).stdout, build) == {"meander"}
    again = make("-j2", "cohort", cohort_dir=cases, build=build)
    assert again.returncode == 0, again.stdout + again.stderr
    assert built(build, "meander") > before["meander"] and built(build, "s_bend") == before["s_bend"]

    # so does a touched input file (the dependencies come from the case file)
    os.utime(tmp_path / "data" / "cohort" / "s_bend" / "surface.ply")
    assert builds_in(make("-n", "cohort", cohort_dir=cases, build=build).stdout, build) == {"s_bend"}


@pytest.mark.slow
@needs_make
def test_a_broken_case_fails_its_row_and_the_others_still_build(tmp_path):
    cases, build = temporary_cohort(tmp_path), tmp_path / "build"
    broken = (cases / "meander.yaml").read_text().replace("knot_spacing_mm", "knot_spacng_mm")
    (cases / "broken.yaml").write_text(broken)
    (cases / "missing.yaml").write_text("final: {centerline: ../nowhere/centerline.vtp}\n")
    result = make("-j2", "cohort", cohort_dir=cases, build=build)
    assert result.returncode != 0
    assert "2 of 4 case(s) failed (broken, missing)" in result.stderr
    rows = summary(build)
    statuses = [rows[name]["status"] for name in ("broken", "meander", "missing", "s_bend")]
    assert statuses == ["failed", "ok", "failed", "ok"]
    assert "unknown key 'knot_spacng_mm'" in rows["broken"]["message"]
    assert "final.centerline: file not found" in rows["missing"]["message"]
    for name in ("broken", "missing"):
        assert not (build / name / "manifest.json").exists()  # no stamp for a failed case
        assert rows[name]["message"][:40] in (build / f"{name}.log").read_text().replace("\n", " ")
        assert json.loads((build / f"{name}.status.json").read_text())["exit_code"] == 2
    # the failed cases are tried again next time; the good ones are left alone
    assert builds_in(make("-n", "cohort", cohort_dir=cases, build=build).stdout, build) == {"broken", "missing"}


def test_a_designed_case_row_carries_the_chain_deviation_and_tip_error(tmp_path):
    # issue 30: the design stage's manifest figures reach the cohort summary; a case without a design leaves them blank
    design = {"designed": True, "links": 5, "meets_tolerance": True, "chain_max_deviation_mm": 0.47,
              "tip_error_mm": 0.12, "tip_error_deg": 4.1, "breaks": [0.0, 1.0]}
    for name, metrics in (("designed", {"design": design}), ("plain", {"design": {"designed": False}})):
        (tmp_path / name).mkdir()
        manifest = {"metrics": metrics, "outputs": [], "case": {"export": {}}}
        (tmp_path / name / "manifest.json").write_text(json.dumps(manifest))
    designed = cohort.manifest_figures(tmp_path / "designed")
    assert (designed["chain_deviation_mm"], designed["tip_error_mm"], designed["tip_error_deg"]) == (0.47, 0.12, 4.1)
    plain = cohort.manifest_figures(tmp_path / "plain")
    assert (plain["chain_deviation_mm"], plain["tip_error_mm"], plain["tip_error_deg"]) == ("", "", "")
    assert {"chain_deviation_mm", "tip_error_mm", "tip_error_deg"} <= set(cohort.SUMMARY_COLUMNS)
