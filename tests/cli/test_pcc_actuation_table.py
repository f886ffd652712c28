"""`pcc reconstruct` reads a build's actuation.csv as it is: seed 003's inverse at each section's own angles."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.kinematics import pcc
from softdesign.kinematics.chamber_lengths import chamber_lengths_from_arc
from softdesign.pipeline.stages.actuation import table_text

runner = CliRunner()
#: The issue's round-trip bound, mm (1/mm, rad); float repr in the CSV leaves round-off only.
ROUND_TRIP_TOL = 1e-6
KAPPA = np.array([[0.0, 0.0, 0.0], [0.01, 0.03, 0.02]])  # (q, section) 1/mm
PHI = np.array([[0.0, 0.0, 0.0], [0.4, -2.5, 3.0]])
LENGTH = np.array([[20.0, 25.0, 30.0], [20.5, 24.0, 31.0]])
D = 2.0
FIRST = np.deg2rad([90.0, 130.0, 170.0])  # the layout's i * 120 / n turn for n = 3


def write_table(path: Path) -> None:
    rows = []
    for k, q in enumerate((0.0, 1.0)):
        for i in range(3):
            lengths = chamber_lengths_from_arc(KAPPA[k, i], PHI[k, i], LENGTH[k, i], D, FIRST[i])
            rows += [{"q": q, "export": 1, "section": i + 1, "chamber": j + 1,
                      "angle_deg": float(np.rad2deg(FIRST[i]) + 120.0 * j), "distance_mm": D,
                      "length_mm": float(lengths[j]), "extension": 1.0, "arc_kappa": KAPPA[k, i],
                      "arc_phi": PHI[k, i], "arc_length_mm": LENGTH[k, i], "arc_misfit_mm": 0.0}
                     for j in range(3)]
    path.write_text(table_text(rows))


def test_round_trip_returns_every_arc_and_the_chain(tmp_path: Path) -> None:
    write_table(tmp_path / "actuation.csv")
    result = runner.invoke(app, ["pcc", "reconstruct", str(tmp_path / "actuation.csv"), "--shapes-dir",
                                 str(tmp_path / "shapes")])
    assert result.exit_code == 0, result.output
    with (tmp_path / "shapes" / "tips.csv").open() as handle:
        tips = list(csv.DictReader(handle))
    for k, tip in enumerate(tips):
        for name, want in (("kappa", KAPPA[k]), ("phi", PHI[k]), ("length", LENGTH[k])):
            got = [float(tip[f"{name}_{i}"]) for i in range(1, 4)]
            np.testing.assert_allclose(got, want, rtol=0, atol=ROUND_TRIP_TOL)
        chain = pcc.chain_transforms(pcc.transform_from_arc(KAPPA[k], PHI[k], LENGTH[k]))[-1]
        np.testing.assert_allclose([float(tip[c]) for c in ("tip_x", "tip_y", "tip_z")], chain[:3, 3], rtol=0,
                                   atol=ROUND_TRIP_TOL)
    assert np.linalg.norm(chain[:3, 3] - [0, 0, LENGTH[1].sum()]) > 1.0  # the bent chain is not the straight one


def test_a_table_whose_chambers_are_not_120_degrees_apart_is_refused(tmp_path: Path) -> None:
    write_table(tmp_path / "actuation.csv")
    text = (tmp_path / "actuation.csv").read_text().replace(",210.0,", ",200.0,", 1)
    (tmp_path / "bad.csv").write_text(text)
    result = runner.invoke(app, ["pcc", "reconstruct", str(tmp_path / "bad.csv"), "--shapes-dir", str(tmp_path / "o")])
    assert result.exit_code == 2 and "120 deg" in result.stderr


def test_a_d_that_contradicts_the_table_is_refused(tmp_path: Path) -> None:
    write_table(tmp_path / "actuation.csv")
    result = runner.invoke(app, ["pcc", "reconstruct", str(tmp_path / "actuation.csv"), "--d", "3",
                                 "--shapes-dir", str(tmp_path / "o")])
    assert result.exit_code == 2 and "differs from" in result.stderr
