"""Issue 45, the smaller ones: strict yes/no and integer keys, a bare ``actuation:``, control characters in a
material's name, a law too soft to factor, and simulate's refusal of a material without a law.
"""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.config.material import MIN_C1_KPA
from softdesign.pipeline.simulate_run import no_law_error
from tests.helpers.attacks import assert_refused, demo_case

runner = CliRunner()

CUSTOM = {"name": "my silicone", "shore": "00-30", "tensile_strength_mpa": 1.0, "elongation_at_break_pct": 800.0,
          "law": {"kind": "neo-hookean", "c1_kpa": 10.0, "c2_kpa": 0.0, "c3_kpa": 0.0},
          "source": "our test report, table 2"}


def _validate(tmp_path, text: str):
    case = demo_case(tmp_path)
    case.write_text(case.read_text() + text)
    return runner.invoke(app, ["validate", str(case)])


@pytest.mark.parametrize(("text", "key"), [
    ("actuation: {}\nsimulate: {enabled: \"yes\"}\n", "simulate.enabled"),
    ("actuation: {chambers_per_section: 3.0}\n", "actuation.chambers_per_section"),
    ("final:\n  reverse: \"false\"\n", "final"),
], ids=["enabled-yes", "chambers-3.0", "reverse-string"])
def test_a_yes_no_or_integer_key_takes_only_its_own_type(tmp_path, text, key):
    case = demo_case(tmp_path)
    body = case.read_text()
    if text.startswith("final:"):  # put the key into the existing final: block
        body = body.replace("final:\n", "final:\n  reverse: \"false\"\n", 1)
        case.write_text(body)
        result = runner.invoke(app, ["validate", str(case)])
    else:
        result = _validate(tmp_path, text)
    assert_refused(result, key)


def test_a_bare_actuation_line_is_refused_and_explained(tmp_path):
    result = _validate(tmp_path, "actuation:\n")
    assert_refused(result, "actuation", "bare `actuation:`", "actuation: {}")


def test_control_characters_in_a_material_name_never_reach_the_terminal(tmp_path):
    custom = {**CUSTOM, "name": "evil\x1b[2J\x1b[31mred"}
    case = demo_case(tmp_path, material={"custom": custom})
    result = runner.invoke(app, ["validate", str(case)])
    text = assert_refused(result, "material.custom.name", "control character")
    assert "\x1b" not in text


def test_a_law_too_soft_to_factor_is_refused_with_the_value_that_works(tmp_path):
    custom = {**CUSTOM, "law": {**CUSTOM["law"], "c1_kpa": 1e-300}}
    case = demo_case(tmp_path, material={"custom": custom})
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, "c1_kpa", f"{MIN_C1_KPA:g}")


def test_simulate_names_a_preset_without_a_law_and_the_presets_that_have_one(tmp_path):
    case = load_case(demo_case(tmp_path, material={"name": "tpu-85a"}, actuation={}))
    message = str(no_law_error(case, "simulate.enabled"))
    assert "material.name tpu-85a: this preset has no hyperelastic law" in message
    assert "ecoflex-00-30" in message and "material.custom" in message
    no_material = load_case(demo_case(tmp_path, name="bare", actuation={}, material=None))
    assert "the case gives none" in str(no_law_error(no_material, "simulate.enabled"))
