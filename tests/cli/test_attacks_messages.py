"""Messages that pointed the user the wrong way: each now names the right file, key and fix."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import GeometryError
from softdesign.geometry.curves import smooth_curve_from_samples
from softdesign.geometry.frames import FLIP_LIMIT_RAD, framed_curve
from tests.helpers.attacks import demo_case
from tests.helpers.folders import snapshot

runner = CliRunner()


def test_check_names_the_reference_file_when_the_reference_is_broken(prior_build, tmp_path):
    reference = tmp_path / "reference"
    shutil.copytree(prior_build, reference)
    document = json.loads((reference / "kinematics.json").read_text())
    document["poses"][0]["links"] = "broken"
    (reference / "kinematics.json").write_text(json.dumps(document))
    result = runner.invoke(app, ["check", str(prior_build), "--reference", str(reference)])
    assert result.exit_code == 2, result.output
    assert f"{reference / 'kinematics.json'}: pose q=" in result.output
    assert "'links' must be a list" in result.output
    assert str(prior_build / "kinematics.json") not in result.output


def test_a_too_negative_offset_is_told_to_come_closer_to_zero_not_to_get_smaller(prior_build, tmp_path):
    out = tmp_path / "build"
    shutil.copytree(prior_build, out)
    before = snapshot(out)
    radius = json.loads((out / "ingest" / "summary.json").read_text())["centerline"]["radius_range_mm"][0]
    case = demo_case(tmp_path, export={"offset_mm": -(radius + 0.5)})  # deeper than the thinnest radius
    result = runner.invoke(app, ["export", str(case), "--out", str(out)])
    assert result.exit_code == 2  # refused after ingest, before the fit (issue 35 item 5)
    assert "Traceback" not in result.output
    assert "offset_mm" in result.output and "make offset_mm closer to 0 (less negative)" in result.output
    assert "make offset_mm smaller" not in result.output
    assert snapshot(out) == before


def test_a_flip_of_rotation_minimizing_frames_does_not_advise_frames_rmf():
    """A hairpin (175 deg over two 0.1 mm samples) flips even the RMF; the fix is the curve, not the frame mode."""
    t = np.linspace(0.0, 10.0, 101)
    turn = np.deg2rad(175.0)
    out = np.column_stack([10.0 + np.cos(turn) * t[1:], np.sin(turn) * t[1:], 0.0 * t[1:]])
    curve = smooth_curve_from_samples(np.vstack([np.column_stack([t, 0.0 * t, 0.0 * t]), out]))
    with pytest.raises(GeometryError) as err:
        framed_curve(curve, "rmf", label="q = 1")
    message = str(err.value)
    assert f"(limit {FLIP_LIMIT_RAD:g})" in message and "frames: rmf, q = 1" in message
    assert "use frames: rmf" not in message
    assert "resample.smoothing_mm" in message and "kink" in message


def test_a_centerline_that_strays_is_warned_about_naming_the_resample_keys(prior_build, tmp_path):
    """resample.smoothing_mm 2 pulls the demo's centerline 2.7 mm off its axis (radius 2.9 mm) near its ends.

    It made rho negative there (a FitError, then blamed on the centerline); since the end prior holds the
    one-sided ends at the inscribed radius (issue 20) the fit succeeds, and the build warns with the same cause.
    """
    out = tmp_path / "build"
    shutil.copytree(prior_build, out)
    case = demo_case(tmp_path, resample={"smoothing_mm": 2.0})
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    assert "warning: fit: the centerline, resampled every" in result.output
    assert "smoothed by 2 mm (resample.smoothing_mm)" in result.output
    assert "lower resample.smoothing_mm" in result.output
    assert "raise fit.smoothing" not in result.output


def test_a_surface_that_does_not_surround_the_path_is_bad_input_exit_2():
    """It was a FitError (exit 1, "processing failure") though its fix is the case's final.surface or final.path."""
    from softdesign.errors import FitError, InputDataError
    from softdesign.fitting.bspline_surface import FitSettings, fit_radius_surface
    from softdesign.fitting.projection import project_points
    from tests.helpers.analytic import Line

    curve = Line(40.0)
    l, a = np.meshgrid(np.linspace(0.0, 1.0, 40), np.linspace(0.0, 2 * np.pi, 30, endpoint=False))
    beside = curve.points(l.ravel()) + 3.0 * np.column_stack([np.cos(a.ravel()), np.sin(a.ravel()), 0 * l.ravel()])
    with pytest.raises(FitError) as err:
        fit_radius_surface(project_points(curve, beside + np.array([10.0, 0.0, 0.0])), curve.length, FitSettings())
    assert isinstance(err.value, InputDataError) and err.value.exit_code == 2
    assert "check final.surface, final.path and units" in str(err.value)
