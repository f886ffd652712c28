"""`softdesign pcc forward|reconstruct` through the CLI, and the .vtp polyline writer they use."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import InputDataError
from softdesign.io.polylines_vtp import write_polylines_vtp
from softdesign.io.vtk_polydata import polydata_arrays, read_polydata
from softdesign.kinematics import pcc
from tests.helpers.seed_transforms import dh_product, seed_chain

runner = CliRunner()

#: JSON keeps full double precision (repr), so values survive to rounding, mm or dimensionless.
EXACT_TOL = 1e-12
#: tips.csv also writes repr of each float.
CSV_TOL = 1e-12

BENDING = "121,123,125;236,187,269;236,186,268"


def forward_json(*args: str) -> dict:
    result = runner.invoke(app, ["pcc", "forward", *args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def library_forward(lengths, d) -> tuple:
    arcs = pcc.arcs_from_lengths(lengths, d)
    section2prev = pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length)
    return arcs, section2prev, pcc.chain_transforms(section2prev)[-1]


# -- forward ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("d_text, d", [("15", 15.0), ("15,14,13", np.array([15.0, 14.0, 13.0]))])
def test_forward_json_equals_the_library(d_text, d):
    payload = forward_json("--lengths", BENDING, "--d", d_text)
    assert list(payload) == ["sections", "tip", "transform", "dh_convention"]
    assert [list(s) for s in payload["sections"]] == [["kappa", "phi", "length", "theta", "transform", "dh"]] * 3
    lengths = np.array([[121, 123, 125], [236, 187, 269], [236, 186, 268]], float)
    arcs, section2prev, tip2base = library_forward(lengths, d)
    for name in ("kappa", "phi", "length", "theta"):
        np.testing.assert_allclose([s[name] for s in payload["sections"]], getattr(arcs, name), rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose([s["transform"] for s in payload["sections"]], section2prev, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(payload["transform"], tip2base, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(payload["tip"], tip2base[:3, 3], rtol=0, atol=EXACT_TOL)


def test_forward_straight_section_prints_a_pure_translation():
    payload = forward_json("--lengths", "50, 50, 50", "--d", "10")
    np.testing.assert_array_equal(payload["tip"], [0.0, 0.0, 50.0])
    assert payload["sections"][0]["kappa"] == 0.0


def test_forward_json_gives_seed_003s_table_1_for_the_first_section_and_rows_that_multiply_to_each_htm():
    payload = forward_json("--lengths", BENDING, "--d", "15")
    first = payload["sections"][0]
    # the section's arc from its lengths, seed eqs. 3-5 written out (d = 15 mm)
    l1, l2, l3 = 121.0, 123.0, 125.0
    length = (l1 + l2 + l3) / 3
    kappa = 2 * math.sqrt(l1**2 + l2**2 + l3**2 - l1 * l2 - l1 * l3 - l2 * l3) / (15.0 * (l1 + l2 + l3))
    assert first["length"] == pytest.approx(length, rel=0, abs=EXACT_TOL * length)
    assert first["kappa"] == pytest.approx(kappa, rel=0, abs=EXACT_TOL)
    assert math.tan(first["phi"]) == pytest.approx(math.sqrt(3) * (l2 + l3 - 2 * l1) / (3 * (l2 - l3)), rel=1e-12)
    # Table 1: (theta, d, a, alpha) of the five steps, with theta_1 = kappa L and r_1 = 1 / kappa
    phi, theta, r = first["phi"], first["kappa"] * first["length"], 1.0 / first["kappa"]
    table_1 = [
        (phi, 0.0, 0.0, -math.pi / 2),
        (theta / 2, 0.0, 0.0, math.pi / 2),
        (0.0, 2 * r * math.sin(theta / 2), 0.0, -math.pi / 2),
        (theta / 2, 0.0, 0.0, math.pi / 2),
        (-phi, 0.0, 0.0, 0.0),
    ]
    assert [list(row) for row in first["dh"]] == [["theta", "d", "a", "alpha"]] * 5
    got = [[row[c] for c in ("theta", "d", "a", "alpha")] for row in first["dh"]]
    np.testing.assert_allclose(got, table_1, rtol=0, atol=EXACT_TOL * length)
    # every section: the rows' D-H links multiply to its HTM (seed eq. 8), and to the five steps of section 3.2
    for section in payload["sections"]:
        product = dh_product(section["dh"])
        np.testing.assert_allclose(product, section["transform"], rtol=0, atol=EXACT_TOL * section["length"])
        steps = seed_chain(section["kappa"], section["phi"], section["length"])
        np.testing.assert_allclose(product, steps, rtol=0, atol=EXACT_TOL * section["length"])
    assert "Rz(theta) Tz(d) Tx(a) Rx(alpha)" in payload["dh_convention"]


def test_forward_table_shows_each_section_and_the_tip():
    result = runner.invoke(app, ["pcc", "forward", "--lengths", "235,185,268", "--d", "15"])
    assert result.exit_code == 0, result.output
    arcs, _, tip2base = library_forward([[235.0, 185.0, 268.0]], 15.0)
    assert f"{float(arcs.length[0]):.4f}" in result.stdout
    assert f"z = {tip2base[2, 3]:.4f}" in result.stdout
    assert "convention:" in result.stdout


@pytest.mark.parametrize(
    "lengths, d, message",
    [
        ("120,abc,121", "15", "section 1 cable 2: 'abc' is not a number"),
        ("120,121,122;120,0,121", "15", "section 2 cable 2 is 0 mm, expected > 0"),
        ("120,121,122;-5,121,122", "15", "section 2 cable 1 is -5 mm, expected > 0"),
        ("120,121,122", "0", "--d value 1: 0 mm, expected > 0"),
        ("120,121,122", "-2", "--d value 1: -2 mm, expected > 0"),
        ("120,121;125,123,121", "15", "section 1 has 2 length(s) ('120,121'), expected 3"),
        ("120,121,122;125,123,121", "15,14,13", "--d: 3 values for 2 section(s)"),
        ("120,121,122", "nan", "expected a finite number"),
        ("", "15", "no lengths given"),
    ],
)
def test_forward_bad_input_exits_2_with_the_reason(lengths, d, message):
    result = runner.invoke(app, ["pcc", "forward", "--lengths", lengths, "--d", d, "--json"])
    assert result.exit_code == 2
    assert message in result.stderr
    assert result.stdout == ""
    assert "Traceback" not in result.output


def test_help_lists_and_documents_the_commands():
    top = runner.invoke(app, ["pcc", "--help"])
    assert top.exit_code == 0 and "forward" in top.stdout and "reconstruct" in top.stdout
    forward = runner.invoke(app, ["pcc", "forward", "--help"])
    assert forward.exit_code == 0 and "--lengths" in forward.stdout
    reconstruct = runner.invoke(app, ["pcc", "reconstruct", "--help"])
    assert reconstruct.exit_code == 0 and "backbones.vtp" in reconstruct.stdout and "--max-rate" in reconstruct.stdout


# -- reconstruct -----------------------------------------------------------------------------------

HEADER = "t,l11,l12,l13,l21,l22,l23"
GOOD_ROWS = {  # line number in the file -> (time, lengths)
    2: (0.0, [[120.1, 120.2, 120.0], [120.0, 120.0, 120.0]]),
    3: (0.1, [[121.0, 123.0, 125.0], [121.0, 120.0, 119.0]]),
    7: (0.3, [[122.0, 124.0, 126.0], [122.0, 120.5, 119.5]]),
}
CSV_TEXT = "\n".join(
    [
        HEADER,
        "0.0,120.1,120.2,120.0,120,120,120",
        "0.1,121,123,125,121,120,119",
        "0.2,121,-4,125,121,120,119",  # line 4: a negative length
        "0.25,121,123,125,150,120,119",  # line 5: 29 mm in 0.15 s = 193 mm/s > 100
        "0.27,121,12x,125,121,120,119",  # line 6: not a number
        "0.3,122,124,126,122,120.5,119.5",
        "",
    ]
)


@pytest.fixture
def reconstructed(tmp_path):
    readings = tmp_path / "readings.csv"
    readings.write_text(CSV_TEXT)
    out = tmp_path / "out"
    result = runner.invoke(
        app,
        ["pcc", "reconstruct", str(readings), "--d", "15,12", "--shapes-dir", str(out),
         "--max-rate", "100", "--points-per-section", "7"],
    )
    return result, out


def test_reconstruct_writes_tips_matching_the_library(reconstructed):
    result, out = reconstructed
    assert result.exit_code == 0, result.output
    assert "3 row(s) accepted, 3 rejected" in result.stdout
    with open(out / "tips.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(GOOD_ROWS)
    for row, (time, lengths) in zip(rows, GOOD_ROWS.values(), strict=True):
        arcs, _, tip2base = library_forward(lengths, np.array([15.0, 12.0]))
        assert float(row["time"]) == time
        tip = [float(row[k]) for k in ("tip_x", "tip_y", "tip_z")]
        np.testing.assert_allclose(tip, tip2base[:3, 3], rtol=0, atol=CSV_TOL)
        rotation = [float(row[f"r{i}{j}"]) for i in range(1, 4) for j in range(1, 4)]
        np.testing.assert_allclose(rotation, tip2base[:3, :3].ravel(), rtol=0, atol=CSV_TOL)
        for s in range(2):
            for name in ("kappa", "phi", "length", "theta"):
                np.testing.assert_allclose(float(row[f"{name}_{s + 1}"]), getattr(arcs, name)[s], rtol=0, atol=CSV_TOL)


def test_reconstruct_reports_each_rejected_row_with_its_reason(reconstructed):
    result, out = reconstructed
    with open(out / "rejected.csv", newline="") as handle:
        rejected = {int(r["line"]): r["reason"] for r in csv.DictReader(handle)}
    assert sorted(rejected) == [4, 5, 6]
    assert "section 1 cable 2: length -4 mm is not > 0" in rejected[4]
    assert "section 2 cable 1 changed +29 mm" in rejected[5] and "> --max-rate 100" in rejected[5]
    assert "'12x' is not a number" in rejected[6]
    for line in (4, 5, 6):
        assert f"line {line} (time" in result.stderr
    assert "rejected" not in result.stdout.replace("3 rejected", "").replace("rejected.csv", "")


def test_reconstruct_backbones_vtp_holds_one_polyline_per_accepted_row(reconstructed):
    _, out = reconstructed
    poly = read_polydata(out / "backbones.vtp")
    points, point_data, cell_data = polydata_arrays(poly)
    per_row = 2 * (7 - 1) + 1
    assert poly.GetNumberOfLines() == len(GOOD_ROWS) and len(points) == per_row * len(GOOD_ROWS)
    np.testing.assert_array_equal(cell_data["line"], list(GOOD_ROWS))
    np.testing.assert_array_equal(cell_data["time"], [t for t, _ in GOOD_ROWS.values()])
    for name in ("N", "B", "T"):
        assert point_data[name].shape == (len(points), 3)
    for i, (_, lengths) in enumerate(GOOD_ROWS.values()):
        arcs = pcc.arcs_from_lengths(lengths, np.array([15.0, 12.0]))
        poses = pcc.sample_backbone_poses(arcs.kappa, arcs.phi, arcs.length, 7)
        rows = slice(i * per_row, (i + 1) * per_row)
        np.testing.assert_allclose(points[rows], poses[:, :3, 3], rtol=0, atol=EXACT_TOL)
        np.testing.assert_allclose(point_data["T"][rows], poses[:, :3, 2], rtol=0, atol=EXACT_TOL)
    assert not any(p.name.endswith(".tmp") for p in out.iterdir())


def test_reconstruct_without_max_rate_accepts_the_jump(tmp_path):
    readings = tmp_path / "readings.csv"
    readings.write_text(CSV_TEXT)
    args = ["pcc", "reconstruct", str(readings), "--d", "15", "--shapes-dir", str(tmp_path / "out")]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "4 row(s) accepted, 2 rejected" in result.stdout


@pytest.mark.parametrize(
    "text, d, message",
    [
        (HEADER + "\n0,1,2,3,4,5\n", "15", "readings.csv line 2: 6 column(s), expected 7"),
        ("t,a,b\n0,1,2\n", "15", "readings.csv line 1: the header has 3 column(s)"),
        ("0,1,2,3\n", "15", "readings.csv line 1: the first row is numbers, not a header"),
        ("", "15", "the file is empty"),
        (CSV_TEXT, "15,14,13", "--d: 3 values for 2 section(s) in"),
        ("t,a,b,c\n0,-1,2,3\n", "15", "no row was usable"),
    ],
)
def test_reconstruct_bad_file_exits_2_naming_the_file(tmp_path, text, d, message):
    readings = tmp_path / "readings.csv"
    readings.write_text(text)
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", d, "--shapes-dir", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert message in result.stderr
    assert "Traceback" not in result.output


def test_reconstruct_missing_file_and_bad_rate_exit_2(tmp_path):
    missing = runner.invoke(
        app, ["pcc", "reconstruct", str(tmp_path / "nope.csv"), "--d", "15", "--shapes-dir", str(tmp_path)]
    )
    assert missing.exit_code == 2 and "nope.csv: readings file not found" in missing.stderr
    readings = tmp_path / "readings.csv"
    readings.write_text(CSV_TEXT)
    rate = runner.invoke(
        app, ["pcc", "reconstruct", str(readings), "--d", "15", "--shapes-dir", str(tmp_path), "--max-rate", "0"]
    )
    assert rate.exit_code == 2 and "--max-rate must be a finite number > 0" in rate.stderr


# -- the .vtp writer -------------------------------------------------------------------------------


def test_polyline_writer_round_trips_points_and_arrays(tmp_path):
    rng = np.random.default_rng(3)
    lines = [rng.normal(size=(5, 3)), rng.normal(size=(1, 3)), rng.normal(size=(8, 3))]
    frames = [rng.normal(size=(len(p), 3)) for p in lines]
    scalars = [rng.normal(size=len(p)) for p in lines]
    path = write_polylines_vtp(tmp_path / "lines.vtp", lines, {"N": frames, "s": scalars}, {"id": [7, 8, 9]})
    assert b'format="binary"' in path.read_bytes() and b"vtkZLibDataCompressor" in path.read_bytes()
    poly = read_polydata(path)
    points, point_data, cell_data = polydata_arrays(poly)
    np.testing.assert_array_equal(points, np.concatenate(lines))
    np.testing.assert_array_equal(point_data["N"], np.concatenate(frames))
    np.testing.assert_array_equal(point_data["s"], np.concatenate(scalars))
    np.testing.assert_array_equal(cell_data["id"], [7, 8, 9])
    assert [poly.GetCell(i).GetNumberOfPoints() for i in range(3)] == [5, 1, 8]
    empty = read_polydata(write_polylines_vtp(tmp_path / "empty.vtp", []))
    assert empty.GetNumberOfPoints() == 0 and empty.GetNumberOfLines() == 0


def test_polyline_writer_rejects_mismatched_arrays(tmp_path):
    with pytest.raises(InputDataError, match=r"polyline 1: expected an \(n, 3\) array"):
        write_polylines_vtp(tmp_path / "x.vtp", [np.zeros((2, 3)), np.zeros((2, 2))])
    with pytest.raises(InputDataError, match=r"point array 'N', polyline 0: expected \(2,\) or \(2, c\)"):
        write_polylines_vtp(tmp_path / "x.vtp", [np.zeros((2, 3))], {"N": [np.zeros((3, 3))]})
    with pytest.raises(InputDataError, match="non-finite"):
        write_polylines_vtp(tmp_path / "x.vtp", [np.full((2, 3), np.nan)])
    assert not list(tmp_path.iterdir())


def test_reconstruct_rejects_a_row_that_goes_back_in_time(tmp_path):
    readings = tmp_path / "readings.csv"
    readings.write_text("time,a,b,c\n0,100,100,100\n0.1,100,101,102\n0.05,100,101,102\n")
    args = ["pcc", "reconstruct", str(readings), "--d", "10", "--shapes-dir", str(tmp_path / "out")]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    with open(tmp_path / "out" / "rejected.csv", newline="") as handle:
        rejected = list(csv.reader(handle))
    assert rejected == [
        ["line", "time", "reason"],
        ["4", "0.05", "time 0.05 s is not after the previous accepted row (line 3, time 0.1 s)"],
    ]
