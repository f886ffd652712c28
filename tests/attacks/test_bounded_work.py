"""Issue 45, unbounded work: every input's size and rows are checked before it is hashed or parsed.

Synthetic inputs keep these fast: sparse files (a 300 GB surface takes no disk), an ``.npy`` header claiming
12 million points over a sparse body, a million short CSV rows (a few MB).
"""

from __future__ import annotations

import io
import time

import numpy as np
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.cli.pcc_bounds import MAX_LENGTH_MM, MAX_READINGS_ROWS, MAX_REJECTED_NOTES, MAX_SECTIONS
from softdesign.io.centerline import MAX_CENTERLINE_POINTS
from tests.helpers.attacks import assert_refused, demo_case

runner = CliRunner()
#: A refusal before the work must come this fast, s (in-process: no start-up; a loaded machine).
REFUSED_WITHIN_S = 20.0


def _timed(args: list[str]):
    start = time.perf_counter()
    result = runner.invoke(app, args)
    return result, time.perf_counter() - start


def test_build_refuses_a_300_gb_sparse_surface_before_hashing_it(tmp_path):
    surface = tmp_path / "huge.stl"
    with surface.open("wb") as handle:
        handle.truncate(300 * 10**9)  # sparse: no disk used
    case = demo_case(tmp_path, final={"surface": str(surface)})
    result, seconds = _timed(["build", str(case), "--out", str(tmp_path / "b")])
    assert_refused(result, "huge.stl", "above the bound of")
    assert seconds < REFUSED_WITHIN_S, seconds
    assert not (tmp_path / "b").exists()


def test_a_npy_centerline_of_12_million_points_is_refused_from_its_header(tmp_path):
    path = tmp_path / "centerline.npy"
    shape = (12_000_000, 3)
    with path.open("wb") as handle:
        np.lib.format.write_array_header_1_0(handle, {"descr": "<f8", "fortran_order": False, "shape": shape})
        handle.truncate(handle.tell() + 8 * shape[0] * shape[1])  # the data a header promises, sparse
    case = demo_case(tmp_path, final={"centerline": str(path)})
    result, seconds = _timed(["validate", str(case)])
    assert_refused(result, "centerline.npy", f"above the bound of {MAX_CENTERLINE_POINTS:,} centerline points")
    assert seconds < REFUSED_WITHIN_S, seconds


def test_a_csv_centerline_of_too_many_rows_is_refused_before_parsing(tmp_path):
    path = tmp_path / "centerline.csv"
    path.write_bytes(b"x,y,z\n" + b"0,0,0\n" * (MAX_CENTERLINE_POINTS + 1))
    case = demo_case(tmp_path, final={"centerline": str(path)})
    result, seconds = _timed(["validate", str(case)])
    assert_refused(result, "centerline.csv", f"{MAX_CENTERLINE_POINTS + 1:,} rows")
    assert seconds < REFUSED_WITHIN_S, seconds


def test_pcc_reconstruct_refuses_more_readings_rows_than_its_bound(tmp_path):
    path = tmp_path / "readings.csv"
    path.write_bytes(b"t,a,b,c\n" + b"0,1,1,1\n" * (MAX_READINGS_ROWS + 1))
    result, seconds = _timed(["pcc", "reconstruct", str(path), "--d", "3", "--shapes-dir", str(tmp_path / "s")])
    assert_refused(result, "readings.csv", f"above the bound of {MAX_READINGS_ROWS:,} rows")
    assert seconds < REFUSED_WITHIN_S, seconds
    assert not (tmp_path / "s").exists()


def test_pcc_reconstruct_tells_a_bounded_number_of_rejected_rows(tmp_path):
    path = tmp_path / "readings.csv"
    rows = 50
    path.write_text("t,a,b,c\n0,10,10,10\n" + "".join(f"{k + 1},-1,10,10\n" for k in range(rows)))
    result = runner.invoke(app, ["pcc", "reconstruct", str(path), "--d", "3", "--shapes-dir", str(tmp_path / "s")])
    assert result.exit_code == 0, result.output
    told = [line for line in result.stderr.splitlines() if ": rejected: " in line]
    assert len(told) == MAX_REJECTED_NOTES
    assert f"{rows - MAX_REJECTED_NOTES:,} more row(s) rejected" in result.stderr
    assert (tmp_path / "s" / "rejected.csv").read_text().count("\n") == rows + 1  # every one, and the header


def _actuation_csv(path, sections: int, length: float) -> None:
    buffer = io.StringIO()
    buffer.write("q,section,chamber,angle_deg,distance_mm,length_mm\n")
    for section in range(1, sections + 1):
        for chamber, angle in zip((1, 2, 3), (90.0, 210.0, 330.0), strict=True):
            buffer.write(f"0,{section},{chamber},{angle},3,{length!r}\n")
    path.write_text(buffer.getvalue())


def test_an_actuation_table_is_held_to_the_readings_bounds(tmp_path):
    long = tmp_path / "long.csv"
    _actuation_csv(long, 1, 1e300)
    result = runner.invoke(app, ["pcc", "reconstruct", str(long), "--shapes-dir", str(tmp_path / "s")])
    assert_refused(result, "long.csv line 2", f"at most {MAX_LENGTH_MM:g} mm")
    many = tmp_path / "many.csv"
    _actuation_csv(many, MAX_SECTIONS + 1, 10.0)
    result = runner.invoke(app, ["pcc", "reconstruct", str(many), "--shapes-dir", str(tmp_path / "s")])
    assert_refused(result, "many.csv line", f"sections 1 to {MAX_SECTIONS}")
    assert not (tmp_path / "s").exists()


def _tube_stl(path, triangles: int) -> None:
    """A binary STL of an open straight tube (radius 5 mm, 200 mm) with at least ``triangles`` triangles."""
    around = 128
    rings = -(-triangles // (2 * around))
    theta = np.linspace(0.0, 2.0 * np.pi, around, endpoint=False)
    z = np.linspace(0.0, 200.0, rings + 1)
    vertices = np.stack([np.broadcast_to(5.0 * np.cos(theta), (rings + 1, around)),
                         np.broadcast_to(5.0 * np.sin(theta), (rings + 1, around)),
                         np.broadcast_to(z[:, None], (rings + 1, around))], axis=-1).reshape(-1, 3)
    a = (np.arange(rings)[:, None] * around + np.arange(around)).ravel()
    b = (np.arange(rings)[:, None] * around + (np.arange(around) + 1) % around).ravel()
    faces = np.concatenate([np.stack([a, b, a + around], 1), np.stack([b, b + around, a + around], 1)])
    corners = vertices[faces].astype("<f4")
    record = np.zeros(len(faces), dtype=[("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
    record["corners"] = corners
    path.write_bytes(bytes(80) + np.uint32(len(faces)).tobytes() + record.tobytes())


def test_centerline_extraction_refuses_a_surface_over_its_stated_limit_before_the_work(tmp_path):
    from softdesign.centerline.closing import MAX_TRIANGLES

    surface = tmp_path / "tube.stl"
    _tube_stl(surface, 999_000)  # the attack's tube: within the old 1M limit, it took 5.3 GB and 320 s
    for args in (["centerline", str(surface), "--output", str(tmp_path / "c.vtp")],
                 ["init", str(surface), "--output", str(tmp_path / "case.yaml"), "--units", "mm"]):
        result, seconds = _timed(args)
        assert_refused(result, "tube.stl", f"expected 32 to {MAX_TRIANGLES:,}", "decimate it")
        assert seconds < REFUSED_WITHIN_S, seconds
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tube.stl"]
