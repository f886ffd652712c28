"""`softdesign design`: the fewest constant-curvature links on a real case, the case file it writes, bad input."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.kinematics import pcc
from tests.helpers.paths import REPO
from tests.helpers.shared_builds import DEMO_BUILD, DESIGN_DEMO, DESIGNED_BUILD, run_once, workspace

runner = CliRunner()
DEMO = REPO / "configs" / "demo.yaml"
#: JSON carries full doubles.
JSON_TOL = 1e-12
#: Breaks are written with six decimals of normalized l.
BREAKS_TOL = 5e-7


def comparable(case) -> dict:
    """The case without its links, input paths resolved (the designed file may name them from another folder)."""
    dump = case.model_dump(exclude={"links", "blend", "design"})
    dump["final"] = {k: v.resolve() if isinstance(v, Path) else v for k, v in dump["final"].items()}
    return dump


def design_json(case: Path, build: Path, output: Path, *args: str) -> tuple[int, dict, str]:
    result = runner.invoke(app, ["design", str(case), "--out", str(build), "--output", str(output), "--json", *args])
    return result.exit_code, json.loads(result.stdout) if result.stdout.strip() else {}, result.stderr


@pytest.mark.slow
def test_demo_design_meets_the_tolerance_and_its_case_file_differs_only_in_the_links(tmp_path):
    build, output = tmp_path / "build", tmp_path / "designed.yaml"
    code, doc, err = design_json(DEMO, build, output, "--tolerance-mm", "1", "--d", "3")
    assert code == 0, err
    assert {"base_frame", "links", "chain_max_deviation_mm", "tip_error_mm", "tip_error_deg", "meets_tolerance",
            "method", "convention", "breaks"} <= set(doc)
    assert doc["meets_tolerance"] and doc["tolerance_mm"] == 1.0
    links = doc["links"]
    assert [k["index"] for k in links] == list(range(len(links)))
    assert all(k["max_deviation_mm"] <= 1.0 for k in links)
    assert doc["chain_max_deviation_mm"] == max(k["max_deviation_mm"] for k in links)
    np.testing.assert_allclose(doc["breaks"], [links[0]["l_start"]] + [k["l_end"] for k in links], rtol=0,
                               atol=BREAKS_TOL)
    assert doc["breaks"][0] == 0.0 and doc["breaks"][-1] == 1.0
    for k in links:  # seed 003's inverse of each arc, d = 3 mm
        np.testing.assert_allclose(k["chamber_lengths"], pcc.lengths_from_arcs(k["kappa"], k["phi"], k["length"], 3.0),
                                   rtol=0, atol=JSON_TOL)
        assert k["theta"] == pytest.approx(k["kappa"] * k["length"], abs=JSON_TOL)
    designed, original = load_case(output), load_case(DEMO)
    assert designed.links.breaks == [round(b, 6) for b in doc["breaks"]]
    assert designed.blend == "pcc" and designed.design is not None and designed.design.tolerance_mm == 1.0
    assert comparable(designed) == comparable(original)
    assert "# the main vessel; path 1 follows the side branch" in output.read_text()  # the user's comments stay
    # the designed case's links stage takes exactly the design's breaks (blend: pcc: one link per section)
    result = runner.invoke(app, ["links", str(output), "--out", str(tmp_path / "build-designed")])
    assert result.exit_code == 0, result.output
    written = json.loads((tmp_path / "build-designed" / "links" / "links.json").read_text())
    assert written["breaks"] == doc["breaks"]


@pytest.fixture(scope="module")
def demo_designs(tmp_path_factory) -> dict[str, dict]:
    """The demo designed at 2, 1 and 0.5 mm (rmf frames, no --d): each design's JSON, made once for the file."""
    folder = tmp_path_factory.mktemp("designs")
    docs = {}
    for tolerance in ("2", "1", "0.5"):
        code, doc, err = design_json(DEMO, folder / "build", folder / f"d{tolerance}.yaml", "--tolerance-mm",
                                     tolerance)
        assert code == 0, err
        docs[tolerance] = doc
    return docs


@pytest.mark.slow
def test_demo_counts_never_fall_as_the_tolerance_tightens(demo_designs):
    counts = [len(demo_designs[tolerance]["links"]) for tolerance in ("2", "1", "0.5")]
    assert counts == sorted(counts)


def test_designed_case_written_in_another_folder_finds_its_inputs(tmp_path):
    (tmp_path / "v1").mkdir()
    output = tmp_path / "v1" / "designed.yaml"
    code, doc, err = design_json(DEMO, tmp_path / "build", output, "--tolerance-mm", "2")
    assert code == 0, err
    assert load_case(output).final.centerline.resolve() == load_case(DEMO).final.centerline.resolve()
    assert yaml.safe_load(output.read_text())["final"]["centerline"] == os.path.relpath(
        REPO / "data" / "demo" / "centerline.vtp", tmp_path / "v1")


def test_no_design_within_max_links_exits_1_with_the_best_and_writes_nothing(tmp_path):
    output = tmp_path / "designed.yaml"
    code, doc, err = design_json(DEMO, tmp_path / "build", output, "--tolerance-mm", "0.05", "--max-links", "2")
    assert code == 1
    assert not doc["meets_tolerance"] and len(doc["links"]) <= 2 and doc["chain_max_deviation_mm"] > 0.05
    assert "the design misses its bounds" in err and "nothing written" in err
    assert not output.exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--tolerance-mm", "0"], "--tolerance-mm must be a finite number > 0 mm, got 0"),
        (["--tolerance-mm", "-1"], "--tolerance-mm must be a finite number > 0 mm, got -1"),
        (["--tolerance-mm", "1", "--max-links", "0"], "--max-links must be 1 to 40, got 0"),
        (["--tolerance-mm", "1", "--min-link-mm", "0"], "--min-link-mm must be a finite number > 0 mm"),
        (["--tolerance-mm", "1", "--min-link-mm", "5000"], "longer than the centerline"),
        (["--tolerance-mm", "1", "--d", "x"], "--d value 1: 'x' is not a number"),
    ],
)
def test_bad_options_exit_2_with_the_reason(tmp_path, args, message):
    result = runner.invoke(app, ["design", str(DEMO), "--out", str(tmp_path / "b"), "--output",
                                 str(tmp_path / "d.yaml"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "Traceback" not in result.output


def test_output_into_a_missing_folder_or_onto_the_case_exits_2(tmp_path):
    for output, message in [(tmp_path / "no" / "d.yaml", "does not exist"), (DEMO, "is the case file itself")]:
        result = runner.invoke(app, ["design", str(DEMO), "--tolerance-mm", "1", "--output", str(output)])
        assert result.exit_code == 2 and message in result.stderr


def test_help_names_the_json_keys():
    result = runner.invoke(app, ["design", "--help"])
    assert result.exit_code == 0
    for key in ("tolerance_mm", "max_deviation_mm", "chamber_lengths", "tip_error_deg", "base_frame", "tip_frame",
                "--max-links", "--tip-tolerance-mm", "--tip-tolerance-deg"):
        assert key in result.output


def test_aorta_design_keeps_every_link_within_the_tolerance(tmp_path, aorta_dir):
    case = tmp_path / "aorta.yaml"
    case.write_text(yaml.safe_dump({
        "name": "aorta",
        "final": {"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                  "surface": str(aorta_dir / "aorta-surface.stl")},
    }, sort_keys=False))
    counts = []
    for tolerance in ("2", "1", "0.5"):
        code, doc, err = design_json(case, tmp_path / "build", tmp_path / f"d{tolerance}.yaml", "--tolerance-mm",
                                     tolerance)
        assert code == 0, err
        assert all(k["max_deviation_mm"] <= float(tolerance) for k in doc["links"])
        counts.append(len(doc["links"]))
    assert counts == sorted(counts)


@pytest.mark.slow
def test_the_designed_demo_case_builds(tmp_path_factory):
    # the README's design at 1 mm and the build of the case file it writes, run once for the whole test run in the
    # shared workspace (tests/helpers/shared_builds.py; tests/cli/test_readme.py and tests/e2e/test_one_story.py
    # read the same runs): the build's links are the design's breaks, and its meshes are watertight.  Asked for in
    # the README's order: its first command (`make demo`'s build) makes the build/ folder the design writes into
    for args in (DEMO_BUILD, DESIGN_DEMO, DESIGNED_BUILD):
        done = run_once(tmp_path_factory, *args)
        assert done.returncode == 0, f"softdesign {' '.join(args)}:\n{done.stderr[-3000:]}"
    folder = workspace(tmp_path_factory)
    designed = load_case(folder / DESIGN_DEMO[DESIGN_DEMO.index("--output") + 1])
    built = folder / DESIGNED_BUILD[DESIGNED_BUILD.index("--out") + 1]
    design = json.loads((built / "design" / "summary.json").read_text())  # what `design --json` prints
    manifest = json.loads((built / "manifest.json").read_text())
    assert designed.blend == "pcc" and manifest["metrics"]["links"]["breaks"] == design["breaks"]
    np.testing.assert_allclose(design["breaks"], designed.links.breaks, rtol=0, atol=BREAKS_TOL)
    assert all(o["watertight"] for o in manifest["outputs"] if o["path"].startswith("meshes/"))


@pytest.mark.slow
def test_frenet_frames_give_the_same_design_as_rmf(tmp_path, demo_designs):
    # a PCC chain continues without twist: the design measures phi in rmf frames whatever frames: says
    case = yaml.safe_load(DEMO.read_text())
    case.update(name="demo-frenet", frames="frenet", initial={"kind": "arc", "bend_radius_mm": 200.0})
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    frenet = tmp_path / "frenet.yaml"
    frenet.write_text(yaml.safe_dump(case, sort_keys=False))
    rmf_doc = demo_designs["1"]  # the demo's own case, rmf frames
    code, frenet_doc, err = design_json(frenet, tmp_path / "b2", tmp_path / "d2.yaml", "--tolerance-mm", "1")
    assert code == 0, err
    assert frenet_doc["breaks"] == rmf_doc["breaks"]
    for key in ("kappa", "phi", "length", "max_deviation_mm"):
        np.testing.assert_allclose([k[key] for k in frenet_doc["links"]], [k[key] for k in rmf_doc["links"]],
                                   rtol=0, atol=1e-9)
    np.testing.assert_allclose(frenet_doc["tip_error_mm"], rmf_doc["tip_error_mm"], rtol=0, atol=1e-9)


def test_a_straight_vessel_is_one_straight_link_and_without_radii_needs_min_link_mm(tmp_path):
    z = np.linspace(0.0, 40.0, 81)
    (tmp_path / "line.csv").write_text("x,y,z\n" + "".join(f"0,0,{float(v)!r}\n" for v in z))
    case = tmp_path / "line.yaml"
    case.write_text("final: {centerline: line.csv}\n")
    result = runner.invoke(app, ["design", str(case), "--tolerance-mm", "0.1", "--out", str(tmp_path / "b")])
    assert result.exit_code == 2 and "carries no radius" in result.stderr and "--min-link-mm" in result.stderr
    code, doc, err = design_json(case, tmp_path / "b", tmp_path / "d.yaml", "--tolerance-mm", "0.1",
                                 "--min-link-mm", "5")
    assert code == 0, err
    (link,) = doc["links"]
    assert (link["kappa"], link["phi"], link["theta"]) == (0.0, 0.0, 0.0) and doc["breaks"] == [0.0, 1.0]
    np.testing.assert_allclose([link["length"], link["max_deviation_mm"], doc["tip_error_mm"], doc["tip_error_deg"]],
                               [40.0, 0.0, 0.0, 0.0], rtol=0, atol=1e-6)
    assert (tmp_path / "d.yaml").read_text() == (
        "final: {centerline: line.csv}\ndesign: {tolerance_mm: 0.1, max_links: 20, min_link_mm: 5.0}\nblend: pcc\n"
        "links: {breaks: [0.0, 1.0]}\n")
