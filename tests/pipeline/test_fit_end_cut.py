"""The fit stage's end cut (``fit.end_cut``): recorded per end in fit/summary.json, said and warned about.

The tilted-cap vessel's inlet cap (radius 3 mm, tilted theta to the straight centerline) has a rim gap of
r tan(theta): auto cuts the body there, normal keeps the end square and warns above RIM_GAP_TOLERANCE_MM.
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.end_planes import RIM_GAP_TOLERANCE_MM
from softdesign.pipeline.api import build_through
from softdesign.pipeline.stages.fit import describe_fit, fit_metrics
from softdesign.pipeline.stages.fit_notices import fit_notices
from tests.helpers.cases import write_case
from tests.helpers.robust_vessels import write_tilted_cap_vessel

RADIUS, LENGTH = 3.0, 40.0


def fit_of(tmp_path, tilt_deg: float, mode: str):
    centerline, surface = write_tilted_cap_vessel(tmp_path / "tilted", RADIUS, LENGTH, tilt_deg)
    case = write_case(tmp_path, mode, final={"centerline": str(centerline), "surface": str(surface)},
                      links={"count": 2}, fit={"end_cut": mode})
    return build_through(case, tmp_path / "out", target="fit").results["fit"]


@pytest.mark.parametrize("mode", ["auto", "normal"])
def test_the_fit_records_the_cut_per_end_and_warns_only_about_a_large_gap_left_square(tmp_path, mode):
    result = fit_of(tmp_path, 8.0, mode)
    cuts = fit_metrics(result)["end_cut"]
    assert cuts["inlet"]["applied"] == (mode == "auto") and not cuts["outlet"]["applied"]
    np.testing.assert_allclose(cuts["inlet"]["tilt_deg"], 8.0, atol=1e-3)
    assert cuts["inlet"]["rim_gap_mm"] > RIM_GAP_TOLERANCE_MM
    lines = describe_fit(result)
    warned = [n.text for n in fit_notices(result.summary)
              if n.text.startswith("the vessel's flat cap at the inlet is tilted 8.0 deg") and n.place == "inlet"]
    if mode == "auto":
        said = f"inlet: cut at the detected plane (tilt 8.0 deg, rim gap {cuts['inlet']['rim_gap_mm']:.3f} mm)"
        assert said in lines and warned == []
    else:
        assert len(warned) == 1 and "fit.end_cut: auto" in warned[0]
