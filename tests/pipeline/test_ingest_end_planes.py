"""Ingest records each end's plane (manifest ``metrics.ingest.end_planes``): its tilt and rim gap.

Known answer: the tilted-cap vessel (radius r, inlet cap tilted theta to the straight centerline) has a rim
gap of r tan(theta) at the inlet (0.157, 0.422, 0.748 mm at 3, 8, 14 degrees for r = 3 mm) and none at its
square outlet; the tolerance is the sample polygon's sagitta (tests/geometry/test_end_planes.py).  The warning
about a large gap is the fit's, which decides whether the body is cut there (tests/pipeline/test_fit_end_cut.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.config import load_case
from softdesign.pipeline.stages.ingest import ingest_notices, run_ingest
from tests.geometry.test_end_planes import COORD_TOL_MM, SAGITTA, TILT_TOL_DEG
from tests.helpers.cases import straight_tube, write_case
from tests.helpers.robust_vessels import write_tilted_cap_vessel

RADIUS, LENGTH = 3.0, 40.0


@pytest.mark.parametrize("tilt_deg", [3.0, 8.0, 14.0])
def test_ingest_reports_the_tilt_and_rim_gap_of_a_tilted_inlet_cap(tmp_path, tilt_deg):
    centerline, surface = write_tilted_cap_vessel(tmp_path / "tilted", RADIUS, LENGTH, tilt_deg)
    case = write_case(tmp_path, "tilted", final={"centerline": str(centerline), "surface": str(surface)})
    result = run_ingest(load_case(case))
    planes = result.summary["end_planes"]
    inlet, outlet = planes["inlet"], planes["outlet"]
    expected = RADIUS * np.tan(np.radians(tilt_deg))
    assert inlet["kind"] == "flat_cap" and abs(inlet["tilt_deg"] - tilt_deg) < TILT_TOL_DEG
    assert expected * (1.0 - SAGITTA) - COORD_TOL_MM <= inlet["rim_gap_mm"] <= expected + COORD_TOL_MM
    assert outlet["kind"] == "flat_cap" and outlet["tilt_deg"] < TILT_TOL_DEG and outlet["rim_gap_mm"] < COORD_TOL_MM
    # ingest measures; the fit, which decides whether the body is cut there, warns (test_fit_end_cut.py)
    assert not any(n.text.startswith("the vessel's flat cap") for n in ingest_notices(result))


def test_a_vessel_cut_square_at_both_ends_has_no_tilt_and_no_warning(tmp_path):
    centerline, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, "square", final={"centerline": str(centerline), "surface": str(surface)})
    result = run_ingest(load_case(case))
    for plane in result.summary["end_planes"].values():
        assert plane["kind"] == "flat_cap" and plane["tilt_deg"] < TILT_TOL_DEG and plane["rim_gap_mm"] < COORD_TOL_MM
        # the cylinder runs 1 mm past each end of the centerline
        assert abs(plane["axis_offset_mm"] - 1.0) < COORD_TOL_MM
    assert not any(n.kind == "warning" for n in ingest_notices(result))


def test_without_a_surface_nothing_is_measured(tmp_path):
    centerline, _ = straight_tube(tmp_path)
    case = write_case(tmp_path, "bare", final={"centerline": str(centerline)})
    assert run_ingest(load_case(case)).summary["end_planes"] is None
