"""`softdesign pcc design`: one PCC arc per link, fitted to the generalized design.

Known answers first (exact arcs through the fit), then the issue's consistency
test (a centerline made of seed 003 arcs gives those arcs back through the
whole pipeline), then the demo case and bad input.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import ConfigError
from softdesign.geometry.frames import base_normal_from_tangent
from softdesign.geometry.se3 import rotation_from_rotvec
from softdesign.kinematics import pcc
from softdesign.kinematics.pcc_fit import ERROR_KEYS, fit_arc, fit_link, trapezoid_weights
from tests.helpers.cases import write_case
from tests.helpers.paths import REPO

runner = CliRunner()
DEMO = REPO / "configs" / "demo.yaml"

#: Exact arc samples fitted by the solver (relative stopping tolerance 1e-12 on O(1) unknowns): rounding level.
EXACT_KAPPA_TOL = 1e-10  # 1/mm
EXACT_ANGLE_TOL = 1e-9  # rad
EXACT_LENGTH_TOL_MM = 1e-9
#: JSON carries full doubles.
JSON_TOL = 1e-12

# -- a centerline made of seed 003 arcs ---------------------------------------------------------------
#: (kappa 1/mm, phi rad, L mm) of each arc; joints with moderate curvature jumps (0.035 and 0.047 /mm).
ARCS = ((0.05, 0.4, 20.0), (0.07, 0.9, 15.0), (0.04, 0.2, 20.0))
#: Step of the dense polyline and of the case's resampling, mm.
STEP_MM = 0.005
#: Chamber distance, mm: kappa d <= 0.14, every chamber well inside its feasible range.
D_MM = 2.0


def curvature_jumps() -> list[float]:
    """|change of the curvature vector| at the base, each joint and the tip, 1/mm (0 at base and tip)."""
    vectors = [k * np.array([np.cos(p), np.sin(p)]) for k, p, _ in ARCS]
    return [0.0] + [float(np.linalg.norm(b - a)) for a, b in zip(vectors[:-1], vectors[1:], strict=True)] + [0.0]


def joint_angle_rad(link: int) -> float:
    """Bound on the frame error the quintic spline makes at the ends of a link, rad.

    A spline cannot follow a curvature jump dk: its frames near a joint are off
    by about 0.13 h dk (h the sample step; measured and bounded by 0.25 h dk in
    tests/kinematics/test_links_poe.py).  That error tilts the whole link in its {S}.
    """
    jumps = curvature_jumps()
    return 0.25 * STEP_MM * (jumps[link] + jumps[link + 1])


def arcs_polyline(base: np.ndarray) -> np.ndarray:
    """Dense points (n, 3) mm of the arcs chained from ``base``, every STEP_MM of arc length."""
    pose, points = base, []
    for kappa, phi, length in ARCS:
        s = np.linspace(0.0, length, int(round(length / STEP_MM)) + 1)[:-1]
        points.append((pose @ pcc.transform_from_arc(kappa, phi, s))[:, :3, 3])
        pose = pose @ pcc.transform_from_arc(kappa, phi, length)
    return np.concatenate(points + [pose[None, :3, 3]])


def arcs_base() -> np.ndarray:
    """A generic base pose whose N axis is the pipeline's deterministic base normal, so phi is comparable."""
    rotation = rotation_from_rotvec(np.random.default_rng(2024).normal(size=3))
    tangent = rotation[:, 2]
    normal = base_normal_from_tangent(tangent)
    base = np.eye(4)
    base[:3, :3] = np.column_stack([normal, np.cross(tangent, normal), tangent])
    base[:3, 3] = [12.0, -30.0, 7.5]
    return base


def wrapped(angle: float) -> float:
    """An angle difference in (-pi, pi]."""
    return float(math.remainder(angle, 2.0 * math.pi))


# -- known answers through the fit itself ----------------------------------------------------------------
@pytest.mark.parametrize("phi", [0.3, 2.0, -2.5, -0.7, math.pi])
@pytest.mark.parametrize("kappa", [0.0, 1e-7, 0.02, 0.15])
def test_exact_arc_points_give_back_their_arc(kappa, phi):
    length = 20.0
    fractions = np.linspace(0.0, 1.0, 41) ** 1.5  # unequal spacing: the trapezoid weights must cope
    points = pcc.tip_position_from_arc(kappa, phi, length * fractions)
    arc = fit_arc(points, fractions, length_scale=length * 1.07)  # a start value that is off
    np.testing.assert_allclose(arc.kappa, kappa, rtol=0, atol=EXACT_KAPPA_TOL)
    np.testing.assert_allclose(arc.length, length, rtol=0, atol=EXACT_LENGTH_TOL_MM)
    if kappa * length > 1e-6:  # below, the bending plane is not observable to rounding
        np.testing.assert_allclose(wrapped(arc.phi - phi), 0.0, rtol=0, atol=EXACT_ANGLE_TOL)
    if kappa == 0.0:
        assert (arc.kappa, arc.phi, arc.theta) == (0.0, 0.0, 0.0)


def test_an_exact_arc_in_any_frame_has_no_errors_and_a_rolled_end_frame_is_a_rotation_error_only():
    kappa, phi, length, roll = 0.06, -1.1, 30.0, 0.2
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec([0.3, -1.2, 0.5])
    base[:3, 3] = [5.0, 1.0, -4.0]
    poses = base @ pcc.sample_backbone_poses([kappa], [phi], [length], 61)
    arc_length = np.linspace(0.0, length, 61)
    fit = fit_link(poses, arc_length)
    np.testing.assert_allclose([fit.kappa, fit.phi, fit.length], [kappa, phi, length], rtol=0, atol=EXACT_ANGLE_TOL)
    np.testing.assert_allclose([getattr(fit, k) for k in ERROR_KEYS], 0.0, rtol=0, atol=EXACT_LENGTH_TOL_MM)
    # the design's end frame rolled about its own tangent: same backbone, same tangent, rotation error = roll
    poses[-1, :3, :3] = poses[-1, :3, :3] @ rotation_from_rotvec([0.0, 0.0, roll])
    rolled = fit_link(poses, arc_length)
    np.testing.assert_allclose(rolled.tangent_error_rad, 0.0, rtol=0, atol=EXACT_ANGLE_TOL)
    np.testing.assert_allclose(rolled.rotation_error_rad, roll, rtol=0, atol=EXACT_ANGLE_TOL)


def test_an_unevenly_stretched_straight_line_is_an_exact_straight_arc():
    # fractions come from the arc length, so uneven sample spacing along a straight backbone changes nothing
    s = np.linspace(0.0, 10.0, 11) ** 2 / 10.0
    points = np.column_stack([np.zeros_like(s), np.zeros_like(s), s])
    arc = fit_arc(points, s / s[-1], length_scale=s[-1])
    assert (arc.kappa, arc.phi) == (0.0, 0.0)
    np.testing.assert_allclose(arc.length, 10.0, rtol=0, atol=EXACT_LENGTH_TOL_MM)


def test_trapezoid_weights_integrate_exactly_for_linear_functions():
    f = np.array([0.0, 0.1, 0.5, 0.55, 1.0])
    w = trapezoid_weights(f)
    np.testing.assert_allclose([w.sum(), w @ f], [1.0, 0.5], rtol=0, atol=JSON_TOL)


def test_bad_backbones_are_refused():
    with pytest.raises(ConfigError, match="fractions must rise"):
        fit_arc(np.zeros((3, 3)), [0.0, 0.6, 0.5], 1.0)
    with pytest.raises(ConfigError, match=r"n >= 3"):
        fit_arc(np.zeros((2, 3)), [0.0, 1.0], 1.0)


# -- the consistency test: arcs in, the same arcs out ------------------------------------------------
@pytest.fixture(scope="module")
def arcs_design(tmp_path_factory) -> tuple[Path, Path, dict]:
    folder = tmp_path_factory.mktemp("arcs")
    np.save(folder / "centerline.npy", arcs_polyline(arcs_base()))
    lengths = np.array([a[2] for a in ARCS])
    breaks = (np.concatenate([[0.0], np.cumsum(lengths)]) / lengths.sum()).tolist()
    case = write_case(
        folder,
        final={"centerline": "centerline.npy"},
        resample={"spacing_mm": STEP_MM, "smoothing_mm": 0.0, "end_straight_mm": 0.0},
        links={"breaks": breaks},
        export={"q": [0.0, 1.0]},
    )
    out = folder / "build"
    result = runner.invoke(app, ["pcc", "design", str(case), "--d", str(D_MM), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    return case, out, json.loads(result.stdout)


def test_final_shape_made_of_arcs_gives_back_their_kappa_phi_and_length(arcs_design):
    *_, payload = arcs_design
    assert [pose["q"] for pose in payload["poses"]] == [0.0, 1.0]
    for j, (link, (kappa, phi, length)) in enumerate(zip(payload["poses"][1]["links"], ARCS, strict=True)):
        # the spline's frame error at a joint tilts the link in {S} by up to eps; the best arc absorbs a tilt
        # as a change of its bending vector theta (cos phi, sin phi) of about eps (measured <= 0.65 of 2 eps)
        eps = joint_angle_rad(j)
        assert 2 * eps <= 2.1e-4  # i.e. about 1e-4 of the bending angles here (0.8 to 1.05 rad)
        np.testing.assert_allclose(link["kappa"] * length, kappa * length, rtol=0, atol=2 * eps)
        np.testing.assert_allclose(kappa * length * wrapped(link["phi"] - phi), 0.0, rtol=0, atol=2 * eps)
        np.testing.assert_allclose(link["length"], length, rtol=0, atol=2 * eps * length)
        np.testing.assert_allclose(link["theta"], link["kappa"] * link["length"], rtol=0, atol=JSON_TOL)
        # the same tilt moves the backbone by at most eps L; the arc follows it better than that
        assert link["backbone_rms_mm"] <= link["backbone_max_mm"] <= 2 * eps * length
        assert link["tip_error_mm"] <= link["backbone_max_mm"] + JSON_TOL


def test_straight_insertion_shape_is_straight_with_equal_chambers(arcs_design):
    *_, payload = arcs_design
    for link, (_, _, length) in zip(payload["poses"][0]["links"], ARCS, strict=True):
        assert (link["kappa"], link["phi"], link["theta"]) == (0.0, 0.0, 0.0)
        # the straight initial shape has the final shape's length: each link keeps its length
        np.testing.assert_allclose(link["length"], length, rtol=0, atol=1e-6 * length)
        np.testing.assert_allclose(link["chamber_lengths"], [link["length"]] * 3, rtol=0, atol=JSON_TOL)
        np.testing.assert_allclose(link["chamber_strain"], 0.0, rtol=0, atol=JSON_TOL)
        np.testing.assert_allclose([link[k] for k in ERROR_KEYS], 0.0, rtol=0, atol=1e-9)


def test_chamber_strain_shortens_the_chambers_on_the_bending_side(arcs_design):
    *_, payload = arcs_design
    for j, (link, (kappa, phi, length)) in enumerate(zip(payload["poses"][1]["links"], ARCS, strict=True)):
        cosines = np.cos(pcc.ENCODER_ANGLES_RAD - phi)
        # same link length at q = 0 and 1: strain_j = -kappa d cos(a_j - phi) (seed eq. 2 over L)
        expected = -kappa * D_MM * cosines
        eps = joint_angle_rad(j)
        np.testing.assert_allclose(link["chamber_strain"], expected, rtol=0, atol=2 * eps * (1 + 2 * D_MM / length))
        facing = np.abs(cosines) > 0.1  # chambers well off the neutral plane
        assert np.all(np.sign(link["chamber_strain"])[facing] == -np.sign(cosines[facing]))
        # the chambers' mean is the backbone length (the three cosines sum to 0)
        np.testing.assert_allclose(np.mean(link["chamber_lengths"]), link["length"], rtol=0, atol=JSON_TOL * length)


@pytest.mark.parametrize(
    ("d", "message"),
    [
        ("0", "expected > 0"),
        ("-1.5", "expected > 0"),
        ("2,abc", "'abc' is not a number"),
        ("nan", "expected a finite number"),
        ("2,2", "2 values for 3 section(s)"),
        ("2,2,2,2", "4 values for 3 section(s)"),
    ],
)
def test_bad_d_exits_2_with_the_reason(arcs_design, d, message):
    case, out, _ = arcs_design
    result = runner.invoke(app, ["pcc", "design", str(case), "--d", d, "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output


def test_one_d_per_link_is_used_per_link(arcs_design):
    case, out, payload = arcs_design
    result = runner.invoke(app, ["pcc", "design", str(case), "--d", "1,2,3", "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    per_link = json.loads(result.stdout)
    assert per_link["d"] == [1.0, 2.0, 3.0] and payload["d"] == [D_MM] * 3
    for j, d in enumerate([1.0, 2.0, 3.0]):
        link = per_link["poses"][1]["links"][j]
        np.testing.assert_allclose(
            link["chamber_lengths"],
            pcc.lengths_from_arcs(link["kappa"], link["phi"], link["length"], d),
            rtol=0,
            atol=JSON_TOL,
        )


def test_too_few_samples_exits_2(arcs_design):
    case, out, _ = arcs_design
    result = runner.invoke(app, ["pcc", "design", str(case), "--d", "2", "--out", str(out), "--samples", "2"])
    assert result.exit_code == 2


def test_a_chamber_that_would_vanish_is_warned_about(arcs_design):
    case, out, _ = arcs_design
    # kappa d >= 1 on every link with d = 30 mm (kappa >= 0.04 /mm): the table still prints, with a warning
    result = runner.invoke(app, ["pcc", "design", str(case), "--d", "30", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "would be <= 0 mm long" in result.stderr and "link 1" in result.stderr
    assert "worst: link" in result.stdout


# -- the demo case --------------------------------------------------------------------------------------
def test_demo_case_reports_finite_figures(tmp_path):
    result = runner.invoke(app, ["pcc", "design", str(DEMO), "--d", "2", "--out", str(tmp_path / "build"), "--json"])
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert list(payload) == ["d", "poses", "convention", "warnings"]
    assert [pose["q"] for pose in payload["poses"]] == [0.0, 0.5, 1.0]
    keys = [
        "index", "l_start", "l_end", "kappa", "phi", "length", "theta", "dh", "chamber_lengths", "chamber_strain",
        *ERROR_KEYS,
    ]
    for pose in payload["poses"]:
        assert list(pose) == ["q", "links", "worst"] and len(pose["links"]) == 4
        for link in pose["links"]:
            assert list(link) == keys
            # the D-H rows multiply to the link's arc (seed 003's HTM)
            rows = [[row[c] for c in ("theta", "d", "a", "alpha")] for row in link["dh"]]
            np.testing.assert_allclose(pcc.transform_from_dh_table(rows),
                                       pcc.transform_from_arc(link["kappa"], link["phi"], link["length"]),
                                       rtol=0, atol=1e-12 * max(1.0, link["length"]))
            values = [v for k in keys if k != "dh" for v in np.atleast_1d(link[k])]
            assert all(math.isfinite(v) for v in values) and link["kappa"] >= 0.0
        worst = max(pose["links"], key=lambda link: link["backbone_max_mm"])
        assert pose["worst"] == {"index": worst["index"], **{k: worst[k] for k in ERROR_KEYS}}
    # the demo bends in 3D within each link: one arc per link misses it by millimetres, not by rounding
    assert payload["poses"][-1]["worst"]["backbone_max_mm"] > 0.1
    table = runner.invoke(app, ["pcc", "design", str(DEMO), "--d", "2", "--out", str(tmp_path / "build")])
    assert table.exit_code == 0 and "q = 0.5" in table.stdout and "worst: link" in table.stdout


def test_design_help_names_the_json_keys():
    result = runner.invoke(app, ["pcc", "design", "--help"])
    assert result.exit_code == 0
    assert "chamber_strain" in result.output and "--samples" in result.output
