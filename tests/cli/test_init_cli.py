"""`softdesign init`: a commented case file from one's own files, with the unit's evidence; refusals exit 2."""

from __future__ import annotations

import json

import numpy as np
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.io.centerline import read_centerline_network
from softdesign.pipeline.case_template import SCHEMA_FILE
from tests.helpers.folders import snapshot
from tests.helpers.paths import REPO

runner = CliRunner()
DEMO_DATA = REPO / "data" / "demo"


def test_init_writes_a_valid_commented_case_with_the_schema(tmp_path):
    case = tmp_path / "mine.yaml"
    result = runner.invoke(app, ["init", str(DEMO_DATA / "surface.stl"), str(DEMO_DATA / "centerline.vtp"),
                                 "--output", str(case)])
    assert result.exit_code == 0, result.output
    text = case.read_text()
    assert text.startswith(f"# yaml-language-server: $schema={SCHEMA_FILE}\n")
    loaded = load_case(case)  # the written case validates, paths resolved from its own folder
    assert loaded.name == "mine" and loaded.units == "mm"
    assert loaded.final.centerline.resolve() == (DEMO_DATA / "centerline.vtp").resolve()
    # the comments list every path of the file with its length
    network = read_centerline_network(DEMO_DATA / "centerline.vtp")
    assert text.count("#   path ") == len(network.path_ids())
    # the proposed inlet is an end of path 0
    path0 = network.polylines[0].points
    inlet = np.asarray(loaded.final.inlet)
    assert min(np.linalg.norm(path0[0] - inlet), np.linalg.norm(path0[-1] - inlet)) < 1e-3
    schema = json.loads((tmp_path / SCHEMA_FILE).read_text())
    assert schema["title"] == "softdesign case file" and "final" in schema["properties"]


def test_init_with_units_given_skips_the_guess(tmp_path):
    case = tmp_path / "case.yaml"
    result = runner.invoke(app, ["init", str(DEMO_DATA / "surface.stl"), str(DEMO_DATA / "centerline.vtp"),
                                 "--output", str(case), "--units", "mm"])
    assert result.exit_code == 0, result.output
    assert "as given to init" in case.read_text()


def test_init_refuses_to_guess_an_ambiguous_unit(tmp_path):
    # the demo's centerline scaled so that it reads as a human vessel in mm and in cm: no guess is made
    network = read_centerline_network(DEMO_DATA / "centerline.vtp")
    points = network.polylines[0].points
    length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
    scaled = tmp_path / "small.csv"
    factor = 60.0 / length  # 60 units long; radius 2 units
    rows = ["x,y,z,radius"] + [f"{x * factor},{y * factor},{z * factor},2.0" for x, y, z in points]
    scaled.write_text("\n".join(rows) + "\n")
    before = snapshot(tmp_path)
    result = runner.invoke(app, ["init", str(DEMO_DATA / "surface.stl"), str(scaled),
                                 "--output", str(tmp_path / "case.yaml")])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert "cannot tell the files' unit" in result.output and "in mm and in cm" in result.output
    assert "--units" in result.output
    assert snapshot(tmp_path) == before  # nothing written


def test_init_never_overwrites_without_force(tmp_path):
    case = tmp_path / "case.yaml"
    case.write_text("mine\n")
    args = ["init", str(DEMO_DATA / "surface.stl"), str(DEMO_DATA / "centerline.vtp"), "--output", str(case)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and "--force" in result.output
    assert case.read_text() == "mine\n"
    forced = runner.invoke(app, [*args, "--force"])
    assert forced.exit_code == 0, forced.output
    assert yaml.safe_load(case.read_text())["name"] == "case"


def test_init_refuses_a_wrong_output(tmp_path):
    args = ["init", str(DEMO_DATA / "surface.stl"), str(DEMO_DATA / "centerline.vtp"), "--output"]
    for bad, words in ((tmp_path / "case.txt", "expected a .yaml"), (tmp_path / "no" / "c.yaml", "does not exist")):
        result = runner.invoke(app, [*args, str(bad)])
        assert result.exit_code == 2 and words in result.output, result.output


def test_version_and_schema(tmp_path):
    from softdesign import __version__

    version = runner.invoke(app, ["--version"])
    assert version.exit_code == 0 and version.output.strip() == f"softdesign {__version__}"
    printed = runner.invoke(app, ["schema"])
    assert printed.exit_code == 0
    schema = json.loads(printed.output)
    assert schema["$schema"].startswith("https://json-schema.org/") and schema["additionalProperties"] is False
    written = tmp_path / "s.json"
    assert runner.invoke(app, ["schema", "--output", str(written)]).exit_code == 0
    assert json.loads(written.read_text()) == schema
