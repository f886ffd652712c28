"""Attacks through the input files a case names: each refused with exit 2, the file, what it is and the fix.

The builds run over a prior build, which must stay byte for byte as it was.
FIFOs and devices run in a child with a timeout (a reader that waits would hang the test run otherwise).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.helpers.attacks import assert_refused, demo_case, run_limited
from tests.helpers.folders import snapshot


def refused_build(tmp_path: Path, out: Path, *needles: str, **sections) -> str:
    """Build the demo with ``sections`` over ``out``: exit 2 with every needle, ``out`` unchanged; also validate."""
    before = snapshot(out)
    case = demo_case(tmp_path, **sections)
    text = assert_refused(run_limited("build", str(case), "--out", str(out)), *needles)
    assert snapshot(out) == before
    return text


@pytest.mark.parametrize("kind", ["fifo", "folder"])
def test_a_surface_that_is_a_fifo_or_a_folder_is_named_for_what_it_is_not_missing(tmp_path, out, kind):
    surface = tmp_path / "surface.stl"
    os.mkfifo(surface) if kind == "fifo" else surface.mkdir()
    what = "a FIFO (named pipe)" if kind == "fifo" else "a folder"
    text = refused_build(tmp_path, out, "final.surface", f"{surface} is {what}, not a regular file",
                         final={"surface": str(surface)})
    assert "not found" not in text
    case = demo_case(tmp_path, final={"surface": str(surface)})
    assert_refused(run_limited("validate", str(case)), f"{surface} is {what}, not a regular file")


def test_a_character_device_as_the_centerline_is_refused_without_reading_it(tmp_path, out):
    refused_build(tmp_path, out, "final.centerline", "/dev/zero is a character device, not a regular file",
                  final={"centerline": "/dev/zero"})


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_an_unreadable_input_is_refused_by_validate_and_build(tmp_path, out):
    surface = tmp_path / "surface.stl"
    shutil.copy(_demo_surface(), surface)
    surface.chmod(0)
    refused_build(tmp_path, out, "final.surface", "permission denied", final={"surface": str(surface)})
    case = demo_case(tmp_path, final={"surface": str(surface)})
    assert_refused(run_limited("validate", str(case)), "permission denied")


def _demo_surface() -> Path:
    from tests.helpers.paths import REPO

    return REPO / "data" / "demo" / "surface.stl"


def test_garbage_bytes_in_an_stl_are_called_not_an_stl(tmp_path, out):
    surface = tmp_path / "surface.stl"
    surface.write_bytes(bytes(range(256)) * 40)
    text = refused_build(tmp_path, out, str(surface), "not an STL file", "10240 bytes", "re-export",
                         final={"surface": str(surface)})
    assert "charset_normalizer" not in text


@pytest.mark.parametrize(
    ("values", "needle"),
    [
        (np.array([["a", "b", "c"]] * 10), "<U1 values, expected real numbers"),
        (np.ones((10, 3), complex), "complex128 values, expected real numbers"),
    ],
    ids=["string", "complex"],
)
def test_a_npy_centerline_of_strings_or_complex_numbers_is_refused(tmp_path, out, values, needle):
    centerline = tmp_path / "centerline.npy"
    np.save(centerline, values)
    refused_build(tmp_path, out, str(centerline), needle, final={"centerline": str(centerline)})


def test_a_csv_centerline_with_a_nan_radius_names_the_point(tmp_path, out):
    centerline = tmp_path / "centerline.csv"
    rows = [f"{0.0},{0.0},{z},{'nan' if z == 5 else 3.0}" for z in range(0, 40)]
    centerline.write_text("x,y,z,radius\n" + "\n".join(rows) + "\n")
    refused_build(tmp_path, out, str(centerline), "NaN or infinite values at point 5", "fix or remove",
                  final={"centerline": str(centerline)})


def test_an_input_that_fails_to_read_mid_build_is_exit_2_naming_it(tmp_path, out, monkeypatch):
    """An I/O error (EIO: a failing disk, a dropped network mount) while the build hashes an input."""
    import errno

    from typer.testing import CliRunner

    from softdesign.cli import app
    from softdesign.pipeline import runner as pipeline_runner

    surface = _demo_surface()
    real_hash = pipeline_runner.sha256_file

    def failing(path: Path) -> str:
        if Path(path).resolve() == surface.resolve():
            raise OSError(errno.EIO, os.strerror(errno.EIO), str(path))
        return real_hash(path)

    monkeypatch.setattr(pipeline_runner, "sha256_file", failing)
    before = snapshot(out)
    case = demo_case(tmp_path)
    result = CliRunner().invoke(app, ["build", str(case), "--out", str(out)])
    assert_refused(result, str(case), f"{surface}: cannot read this input file (Input/output error)")
    assert snapshot(out) == before
