"""The case file: every shipped config loads; defaults, ranges, unknown keys, paths."""

from __future__ import annotations

import pytest

from softdesign.config import load_case
from softdesign.errors import ConfigError
from tests.helpers.cases import write_case
from tests.helpers.paths import REPO

SHIPPED = sorted(REPO.glob("configs/**/*.yaml"))


def test_there_are_shipped_configs():
    assert any(p.name == "demo.yaml" for p in SHIPPED), "configs/demo.yaml is the README's demo case"


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(REPO)))
def test_every_shipped_config_loads_and_its_inputs_exist(path):
    case = load_case(path)
    assert case.final.centerline.is_file(), f"{path}: {case.final.centerline} missing"
    if case.final.surface is not None:
        assert case.final.surface.is_file(), f"{path}: {case.final.surface} missing"


def test_defaults_are_filled_in_and_paths_are_relative_to_the_case(tmp_path):
    sub = tmp_path / "cases"
    sub.mkdir()
    case = load_case(write_case(sub, final={"centerline": "../data/cl.vtp"}))
    assert case.name == "case"
    assert case.units == "mm"
    assert case.frames == "rmf" and case.blend == "auto"
    assert case.links.count == 4
    assert case.fit.knot_spacing_mm == 1.5 and case.fit.angular_intervals == 24
    assert case.export.q_values() == [0.0, 0.5, 1.0]
    assert case.final.centerline == sub / "../data/cl.vtp"
    assert case.resolved()["final"]["centerline"] == "../data/cl.vtp"


def test_export_frames_are_evenly_spaced_with_both_ends(tmp_path):
    case = load_case(write_case(tmp_path, final={"centerline": "a.vtp"}, export={"frames": 5}))
    assert case.export.q_values() == [0.0, 0.25, 0.5, 0.75, 1.0]


def test_unknown_key_names_the_nearest_valid_key_and_the_line(tmp_path):
    path = write_case(tmp_path, final={"centerline": "a.vtp"}, fit={"knot_spacng_mm": 2})
    with pytest.raises(ConfigError) as err:
        load_case(path)
    text = str(err.value)
    assert "unknown key 'knot_spacng_mm' in fit" in text
    assert "did you mean 'knot_spacing_mm'" in text
    assert f"{path}:4:" in text  # the offending key's line


@pytest.mark.parametrize(
    ("section", "expected"),
    [
        ({"fit": {"knot_spacing_mm": -2}}, "fit.knot_spacing_mm: must be > 0 mm, got -2"),
        ({"fit": {"smoothing": -1}}, "fit.smoothing must be >= 0.0, got -1"),
        ({"units": "inch"}, "units should be 'mm', 'cm' or 'm', got 'inch'"),
        ({"links": {"breaks": [0, 0.6, 0.4, 1]}}, "breaks must be strictly increasing"),
        ({"links": {"count": 2, "length_mm": 5}}, "give one of count, breaks, length_mm; got count, length_mm"),
        ({"export": {"q": [0, 1.5]}}, "q values must lie in [0, 1]"),
        ({"export": {"port_mm": 1.0}}, "port_mm needs wall_mm"),
        ({"initial": {"kind": "arc"}}, "kind: arc needs bend_radius_mm"),
        ({"resample": {"spacing_mm": 0}}, "resample.spacing_mm must be > 0.0, got 0"),
    ],
)
def test_range_and_rule_errors_are_located(tmp_path, section, expected):
    with pytest.raises(ConfigError) as err:
        load_case(write_case(tmp_path, final={"centerline": "a.vtp"}, **section))
    assert expected in str(err.value)


def test_missing_required_key_and_bad_yaml(tmp_path):
    with pytest.raises(ConfigError, match="final is required"):
        load_case(write_case(tmp_path, units="mm"))
    bad = tmp_path / "bad.yaml"
    bad.write_text("final: {centerline: a.vtp\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_case(bad)
    with pytest.raises(ConfigError, match="case file not found"):
        load_case(tmp_path / "absent.yaml")


def test_material_presets_resolve_and_explicit_numbers_win(tmp_path):
    from softdesign.config import Material
    from softdesign.materials import DESIGN_FRACTION, PRESETS

    preset = Material(name="ecoflex-00-30").limits()
    assert preset.max_stretch == 1 + DESIGN_FRACTION * 9.0 and "900 %" in preset.source
    mixed = Material(name="dragon-skin-30", max_stretch=2.0, min_wall_mm=1.2).limits()
    expected = (2.0, PRESETS["dragon-skin-30"].min_stretch, 1.2)
    assert (mixed.max_stretch, mixed.min_stretch, mixed.min_wall_mm) == expected
    assert "overridden" in mixed.source
    custom = Material(max_stretch=1.5).limits()
    assert (custom.name, custom.max_stretch, custom.min_stretch, custom.min_wall_mm) == ("custom", 1.5, None, None)
    for name, limits in PRESETS.items():
        assert limits.max_stretch > 1 and 0 < limits.min_stretch < 1 and limits.min_wall_mm > 0, name
        assert "data sheet" in limits.source or "bulletin" in limits.source, name


def test_a_bad_material_is_refused_with_its_line(tmp_path):
    from softdesign.config import load_case
    from softdesign.errors import ConfigError

    path = tmp_path / "case.yaml"
    path.write_text("final: {centerline: c.vtp}\nmaterial: {name: rubber, max_stretch: 0.5}\n")
    with pytest.raises(ConfigError) as err:
        load_case(path)
    text = str(err.value)
    assert "material.name" in text and "ecoflex-00-30" in text and "material.max_stretch" in text
