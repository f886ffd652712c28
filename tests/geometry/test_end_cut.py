"""Which plane ends the body at each end (softdesign/geometry/end_cut.py): modes, reasons, bounds, the end frame."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.geometry.end_cut import MAX_CUT_TILT_DEG, MIN_CUT_GAP_MM, choose_end_cuts

#: Round-off of a 3x3 rotation applied to a unit vector.
UNIT_TOL = 1e-12


def plane(tilt_deg: float, outward: np.ndarray, radius: float = 3.0) -> dict:
    """An end_planes record whose outward normal leans ``tilt_deg`` from ``outward`` (a unit axis)."""
    t = np.radians(tilt_deg)
    side = np.cross(outward, [0.3, 0.9, 0.1])
    side /= np.linalg.norm(side)
    normal = np.cos(t) * outward + np.sin(t) * side
    return {"kind": "flat_cap", "normal": normal.tolist(), "point_mm": [0.0, 0.0, 0.0], "tilt_deg": tilt_deg,
            "radius_mm": radius, "rim_gap_mm": radius * np.tan(t), "axis_offset_mm": 0.2, "flatness_mm": 0.0}


def frames() -> np.ndarray:
    """Two end frames (columns N, B, T) of a path whose tangent turns from +z to +x."""
    rotation = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # +z -> +x, det +1
    return np.stack([np.eye(3), rotation])


LENGTH_MM = 100.0


def test_auto_cuts_a_tilted_cap_and_keeps_its_normal_in_the_end_frame():
    f = frames()
    planes = {"inlet": plane(8.0, -f[0][:, 2]), "outlet": plane(12.0, f[1][:, 2])}
    cuts = choose_end_cuts("auto", planes, f, LENGTH_MM)
    for k, end in enumerate(("inlet", "outlet")):
        c = cuts[end]
        assert c["applied"] and c["reason"].startswith("flat cap plane detected, through the centerline")
        # at q = 1 the end frame turns the local normal back into the detected one
        np.testing.assert_allclose(f[k] @ np.array(c["normal_local"]), planes[end]["normal"], rtol=0, atol=UNIT_TOL)
        assert (c["tilt_deg"], c["axis_offset_mm"], c["offset_mm"]) == (planes[end]["tilt_deg"], 0.2, 0.0)
    # outward: against T at the inlet, along T at the outlet
    assert cuts["inlet"]["normal_local"][2] < 0 < cuts["outlet"]["normal_local"][2]


def test_auto_keeps_square_ends_where_nothing_is_found_the_gap_is_noise_or_the_tilt_too_large():
    f = frames()
    small = np.degrees(np.arctan(0.5 * MIN_CUT_GAP_MM / 3.0))
    cuts = choose_end_cuts("auto", {"inlet": None, "outlet": plane(small, f[1][:, 2])}, f, LENGTH_MM)
    assert not cuts["inlet"]["applied"] and "no flat cap or open boundary loop" in cuts["inlet"]["reason"]
    assert not cuts["outlet"]["applied"] and cuts["outlet"]["reason"].startswith("rim gap below")
    steep = choose_end_cuts("auto", {"inlet": plane(MAX_CUT_TILT_DEG + 5, -f[0][:, 2]), "outlet": None}, f,
                            LENGTH_MM)
    assert not steep["inlet"]["applied"] and steep["inlet"]["reason"].startswith(f"tilt above {MAX_CUT_TILT_DEG:g}")
    assert choose_end_cuts("auto", None, f, LENGTH_MM)["outlet"]["applied"] is False
    # a 3 mm vessel's 14 deg cap (gap 0.75 mm) on a 8 mm path: its end zone would take more than a quarter
    short = choose_end_cuts("auto", {"inlet": plane(14.0, -f[0][:, 2]), "outlet": None}, f, 8.0)
    assert not short["inlet"]["applied"] and short["inlet"]["reason"].startswith("rim gap too long for a 8.0 mm")


def test_cap_plane_refuses_a_plane_tilted_beyond_the_limit_and_normal_cuts_nothing():
    f = frames()
    planes = {"inlet": plane(MAX_CUT_TILT_DEG + 5, -f[0][:, 2]), "outlet": plane(10.0, f[1][:, 2])}
    with pytest.raises(ConfigError, match=r"fit.end_cut: cap_plane: the inlet's flat cap is tilted 35.0 deg.*"
                                          r"use fit.end_cut: auto or normal"):
        choose_end_cuts("cap_plane", planes, f, LENGTH_MM)
    planes["inlet"] = plane(0.1, -f[0][:, 2])  # a gap auto leaves square: cap_plane cuts it, offset applied
    exact = choose_end_cuts("cap_plane", planes, f, LENGTH_MM)
    assert exact["inlet"]["applied"] and exact["inlet"]["offset_mm"] == 0.2 and exact["outlet"]["offset_mm"] == 0.2
    square = choose_end_cuts("normal", planes, f, LENGTH_MM)
    assert not any(c["applied"] for c in square.values())
    assert square["outlet"]["rim_gap_mm"] == planes["outlet"]["rim_gap_mm"]  # still reported


def test_with_a_mould_auto_turns_each_cut_into_the_parting_plane_and_says_by_how_much():
    # a two-part mould's halves are drawn off along the parting plane's normal: a cap leaning out of that plane
    # would be an undercut, so the cut keeps only its lean within the plane; known answer: the normal with its
    # component along the plane's normal z removed, and that lean arcsin(|n.z|)
    f = frames()
    planes = {"inlet": plane(8.0, -f[0][:, 2]), "outlet": plane(12.0, f[1][:, 2])}
    parting = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])  # B in both end frames, as for a straight q = 0 body
    cut = choose_end_cuts("auto", planes, f, LENGTH_MM)
    turned = choose_end_cuts("auto", planes, f, LENGTH_MM, mould=True, parting_local=parting)
    for end in ("inlet", "outlet"):
        n, m = np.array(cut[end]["normal_local"]), np.array(turned[end]["normal_local"])
        expected = n - n[1] * np.array([0.0, 1.0, 0.0])
        assert turned[end]["applied"] and abs(m[1]) <= UNIT_TOL
        assert np.allclose(m, expected / np.linalg.norm(expected), atol=UNIT_TOL)
        assert turned[end]["parting_lean_deg"] == pytest.approx(np.degrees(np.arcsin(abs(n[1]))), abs=1e-9)
        assert turned[end]["parting_lean_deg"] > 0 and "turned into the mould's parting plane" in turned[end]["reason"]
        assert abs(m[2]) >= abs(n[2])  # the cut leans no more than the detected plane
    # a curved q = 0 body (no parting plane given): square ends, saying why
    kept = choose_end_cuts("auto", planes, f, LENGTH_MM, mould=True)
    for end in ("inlet", "outlet"):
        assert not kept[end]["applied"] and kept[end]["reason"].startswith("export.mould on a curved q = 0 body")
        assert "normal_local" not in kept[end] and kept[end]["tilt_deg"] == planes[end]["tilt_deg"]
