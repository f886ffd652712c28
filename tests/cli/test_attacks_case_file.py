"""Attacks on the case file itself: what is not a small YAML mapping of finite numbers is refused, fast, exit 2.

Each attack runs the real CLI in a child limited to the memory budget
(softdesign.limits) and a timeout, so a hang or a blow-up fails the test
instead of the machine.
"""

from __future__ import annotations

import os

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.case_yaml import MAX_CASE_BYTES, MAX_NESTING, MAX_NODES
from softdesign.limits import MAX_ANGULAR_COUNT, MAX_EXPORT_Q, MAX_HOLDOUT_FOLDS, MAX_LINKS
from tests.helpers.attacks import assert_refused, demo_case, run_limited

runner = CliRunner()

#: The 714-byte "billion laughs" of the issue: nine levels of nine aliases, 9^9 strings when expanded.
ALIAS_BOMB = "\n".join(
    ['name: bomb', 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    + [f"{b}: &{b} [{','.join(['*' + a] * 9)}]" for a, b in zip("abcdefgh", "bcdefghi", strict=True)]
) + "\n"


@pytest.mark.parametrize(
    ("make", "kind"),
    [
        (lambda tmp: (os.mkfifo(tmp / "case.yaml"), tmp / "case.yaml")[1], "a FIFO (named pipe)"),
        (lambda tmp: tmp, "a folder"),
    ],
    ids=["fifo", "folder"],
)
def test_a_case_file_that_is_not_a_regular_file_is_refused_without_hanging(tmp_path, make, kind):
    path = make(tmp_path)
    for command in ("validate", "build"):
        result = run_limited(command, str(path))
        assert_refused(result, str(path), f"is {kind}, not a regular file", "expected a YAML case file")


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_an_endless_device_as_the_case_file_is_refused_at_once(device):
    if not os.path.exists(device):
        pytest.skip(f"{device} not on this system")
    result = run_limited("validate", device)
    assert_refused(result, device, "is a character device, not a regular file")


def test_a_case_file_over_one_megabyte_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_text("name: big\n# " + "x" * MAX_CASE_BYTES + "\n")
    result = run_limited("validate", str(path))
    assert_refused(result, str(path), f"{path.stat().st_size} bytes", f"limit of {MAX_CASE_BYTES} bytes")


def test_the_alias_bomb_is_refused_fast_with_a_short_message(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(ALIAS_BOMB)
    assert len(ALIAS_BOMB) < 1000
    result = run_limited("validate", str(path))
    text = assert_refused(result, str(path), f"more than {MAX_NODES} values (the limit)", "aliases")
    assert len(text) < 1000


def test_deep_nesting_is_refused_with_its_line_not_a_recursion_error(tmp_path):
    path = tmp_path / "deep.yaml"
    depth = 100_000  # far deeper than Python's recursion limit: PyYAML's composer would raise RecursionError
    path.write_text("name: deep\nx: " + "[" * depth + "]" * depth + "\n")
    result = run_limited("validate", str(path))
    assert_refused(result, f"{path}:2:", f"nested more than {MAX_NESTING} deep (the limit)")


def test_a_key_given_twice_is_refused_naming_the_key_and_both_lines(tmp_path):
    case = demo_case(tmp_path)
    text = case.read_text().replace("links:\n", "links:\n  count: 2\n", 1).replace("  count: 4\n", "  count: 4\n", 1)
    case.write_text(text)
    lines = text.splitlines()
    first = next(i for i, line in enumerate(lines, 1) if line == "  count: 2")
    second = next(i for i, line in enumerate(lines, 1) if line == "  count: 4")
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, f"{case}:{second}: key 'count' is given twice", f"first at line {first}", "keep one")


@pytest.mark.parametrize(
    ("section", "key", "shown"),
    [
        ({"export": {"q": [0, 1], "offset_mm": float("nan")}}, "export.offset_mm", "nan"),
        ({"export": {"q": [0, 1], "wall_mm": float("inf")}}, "export.wall_mm", "inf"),
        ({"final": {"inlet": [0.0, float("nan"), 0.0]}}, "final.inlet.1", "nan"),
        ({"fit": {"knot_spacing_mm": float("nan")}}, "fit.knot_spacing_mm", "nan"),
        ({"links": {"breaks": [0.0, float("nan"), 1.0]}}, "links.breaks.1", "nan"),
        ({"resample": {"smoothing_mm": "1e400"}}, "resample.smoothing_mm", "'1e400'"),
        ({"initial": {"kind": "straight", "length_mm": float("inf")}}, "initial.length_mm", "inf"),
    ],
    ids=["offset-nan", "wall-inf", "inlet-nan", "knots-nan", "breaks-nan", "1e400", "length-inf"],
)
def test_validate_refuses_nan_and_inf_in_every_numeric_key(tmp_path, section, key, shown):
    if "final" in section:
        case = demo_case(tmp_path)
        text = case.read_text().replace("final:\n", "final:\n  inlet: [0.0, .nan, 0.0]\n", 1)
        case.write_text(text)
    else:
        case = demo_case(tmp_path, **section)
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, key, shown, "finite number")


@pytest.mark.parametrize(
    ("links", "shown"),
    [({"count": True}, "True"), ({"count": 1e30}, "1e+30"), ({"count": 2.0}, "2.0")],
    ids=["bool", "1e30", "float"],
)
def test_an_integer_key_refuses_bools_and_floats(tmp_path, links, shown):
    case = demo_case(tmp_path, links=links)
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, "links.count must be a whole number", f"got {shown}")


@pytest.mark.parametrize(
    ("section", "key", "limit"),
    [
        ({"fit": {"holdout_folds": 1000000}}, "fit.holdout_folds", MAX_HOLDOUT_FOLDS),
        ({"links": {"count": 100000}}, "links.count", MAX_LINKS),
        ({"export": {"frames": 1000000}}, "export.frames", MAX_EXPORT_Q),
        ({"export": {"angular_count": 1000000}}, "export.angular_count", MAX_ANGULAR_COUNT),
        ({"resample": {"count": 1000000000}}, "resample.count", 50000),
    ],
    ids=["folds", "links", "frames", "angular", "resample"],
)
def test_counts_above_their_limit_are_refused_by_validate_naming_key_value_and_limit(tmp_path, section, key, limit):
    case = demo_case(tmp_path, **section)
    result = run_limited("validate", str(case))
    text = assert_refused(result, key, f"must be <= {limit}", "softdesign/limits/__init__.py", "2 GiB")
    assert len(text) < 2000


def test_holdout_folds_written_as_1e6_names_the_key(tmp_path):
    case = demo_case(tmp_path)
    case.write_text(case.read_text().replace("fit:\n", "fit:\n  holdout_folds: 1e6\n", 1))
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, "fit.holdout_folds must be a whole number", "got '1e6'")


def test_five_thousand_q_values_are_refused_with_a_short_message(tmp_path):
    case = demo_case(tmp_path, export={"q": [i / 5000 for i in range(5001)]})
    result = run_limited("validate", str(case))
    text = assert_refused(result, "export.q has more than", f"{MAX_EXPORT_Q} entries (the limit)")
    assert len(text) < 2000


def test_the_most_frames_allowed_still_give_every_mesh_its_own_name(tmp_path):
    """export.frames is bounded by MAX_EXPORT_Q = 1001, where q steps by 0.001: three decimals still tell them apart."""
    from softdesign.config import load_case
    from softdesign.pipeline.stages.export import mesh_name

    case = load_case(demo_case(tmp_path, export={"q": None, "frames": MAX_EXPORT_Q}))
    names = {mesh_name(q, "stl") for q in case.export.q_values()}
    assert len(names) == MAX_EXPORT_Q
