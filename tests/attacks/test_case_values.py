"""Issue 36: case-file values that crashed, or were accepted without a word, are refused with exit 2.

Each case is written here and checked through ``softdesign validate`` in
process (CliRunner): exit 2, no traceback, the line or key named.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.attacks import assert_refused, run_limited
from tests.helpers.cases import straight_tube

runner = CliRunner()


def _validate(tmp_path, text: str):
    path = tmp_path / "case.yaml"
    path.write_text(text)
    return runner.invoke(app, ["validate", str(path)])


@pytest.mark.parametrize(
    ("text", "needles"),
    [
        ("name: x\nfit: {knot_spacing_mm: " + "9" * 5000 + "}\n", ["case.yaml:2", "integer of 5000 characters"]),
        ("name: x\nzz: &a [*a]\n", ["case.yaml:2", "contain itself"]),
        ("name: x\nfit: {knot_spacing_mm: 1:30}\n", ["fit.knot_spacing_mm", "'1:30'"]),
        ("name: x\nbase: &b {knot_spacing_mm: 2}\nfit:\n  <<: *b\n  knot_spacing_mm: 3\n", ["case.yaml:4", "<<"]),
        ("name: x\nresample: {count: 100, spacing_mm: 0.5}\n", ["resample", "give one of count, spacing_mm"]),
        ("name: x\nexport: {formats: []}\n", ["export.formats", "at least 1"]),
    ],
    ids=["4300-digit-integer", "self-alias", "sexagesimal", "merge-key", "resample-double-rule", "no-formats"],
)
def test_a_case_value_that_crashed_or_passed_silently_is_refused(tmp_path, text, needles):
    assert_refused(_validate(tmp_path, text), *needles)


def test_a_long_list_is_refused_fast_and_not_blamed_on_aliases(tmp_path):
    text = "name: big\nexport:\n  q: [" + ",".join(["0.5"] * 240_000) + "]\n"  # 960 kB, no alias
    start = time.perf_counter()
    message = assert_refused(_validate(tmp_path, text), "more than 100000 values")
    assert time.perf_counter() - start < 15.0  # took 40 to 77 s before, on a loaded machine
    assert "alias" not in message


def test_nan_vertices_are_refused_with_their_count(tmp_path):
    import trimesh

    centerline, _ = straight_tube(tmp_path)
    tube = trimesh.creation.cylinder(radius=3.0, height=42.0, sections=48)
    vertices = tube.vertices.copy()
    vertices[[5, 7]] = np.nan
    trimesh.Trimesh(vertices, tube.faces, process=False).export(tmp_path / "nan.ply")
    case = tmp_path / "nan.yaml"
    case.write_text(f"name: nan\nfinal: {{centerline: {centerline}, surface: {tmp_path / 'nan.ply'}}}\n"
                    "initial: {kind: straight}\n")
    result = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "build")])
    assert_refused(result, "nan.ply", "2 of its", "NaN or infinite")


def test_an_obj_with_a_latin1_comment_reads(tmp_path):
    import trimesh

    from softdesign.io.surface import read_surface

    tube = trimesh.creation.cylinder(radius=3.0, height=20.0, sections=24)
    text = trimesh.exchange.obj.export_obj(tube)
    path = tmp_path / "latin1.obj"
    path.write_bytes(b"# vaisseau r\xe9el (Latin-1)\n" + text.encode("ascii"))  # one byte that is not UTF-8
    vertices, faces = read_surface(path)
    assert len(faces) == len(tube.faces)
    np.testing.assert_allclose(np.sort(vertices, axis=0), np.sort(tube.vertices, axis=0), atol=1e-6)


@pytest.mark.parametrize(
    ("edit", "needles"),
    [
        (("fit/summary.json", "{}"), ["fit/summary.json", "changed since the build"]),
        (("manifest.json", None), ["manifest.json", "lacks what a build writes", "metrics"]),
    ],
    ids=["fit-summary-emptied", "manifest-without-metrics"],
)
def test_report_on_a_build_lacking_what_it_expects_is_refused(out, edit, needles):
    import json

    name, text = edit
    if text is None:
        manifest = json.loads((out / name).read_text())
        del manifest["metrics"]
        text = json.dumps(manifest)
    (out / name).write_text(text)
    assert_refused(run_limited("report", str(out), "--jobs", "1"), *needles)


