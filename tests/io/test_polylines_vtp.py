"""polylines_vtp_bytes: the bytes write_polylines_vtp writes, for callers that stage or encode files themselves."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import InputDataError
from softdesign.io.polylines_vtp import polylines_vtp_bytes, write_polylines_vtp


def test_bytes_are_the_written_file(tmp_path):
    rng = np.random.default_rng(3)
    lines = [rng.random((40, 3)), rng.random((7, 3))]
    point_arrays = {"N": [rng.random((40, 3)), rng.random((7, 3))], "l": [np.linspace(0, 1, 40), np.linspace(0, 1, 7)]}
    cell_arrays = {"TractIds": np.array([0, 1])}
    written = write_polylines_vtp(tmp_path / "lines.vtp", lines, point_arrays, cell_arrays)
    assert polylines_vtp_bytes(lines, point_arrays, cell_arrays) == written.read_bytes()


def test_bad_polyline_is_refused_as_the_writer_refuses_it():
    with pytest.raises(InputDataError, match="polyline 0: expected an \\(n, 3\\) array"):
        polylines_vtp_bytes([np.zeros((4, 2))])
