"""`softdesign materials`, the preset data with sources, and a user's own material refused when incomplete."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.materials.data import KPA_PER_UNIT, material_presets
from tests.helpers.cases import write_case

runner = CliRunner()
#: Smooth-On's technical bulletins as issue 32 quotes them: tensile strength, 100 % modulus (psi), elongation (%).
SMOOTH_ON = {"ecoflex-00-10": (120, 8, 800), "ecoflex-00-20": (160, 8, 845), "ecoflex-00-30": (200, 10, 900),
             "ecoflex-00-50": (315, 12, 980), "dragon-skin-10": (475, 22, 1000), "dragon-skin-20": (550, 49, 620),
             "dragon-skin-30": (500, 86, 364)}


def test_presets_carry_the_datasheet_values_with_sources():
    presets = material_presets()
    for name, (tensile, modulus, elongation) in SMOOTH_ON.items():
        p = presets[name]
        np.testing.assert_allclose(p.tensile_strength_kpa, tensile * KPA_PER_UNIT["psi"], rtol=1e-12)
        np.testing.assert_allclose(p.modulus_100_kpa, modulus * KPA_PER_UNIT["psi"], rtol=1e-12)
        assert p.elongation_at_break_pct == elongation and "Smooth-On" in p.source and "table" in p.source
        assert p.max_stretch == 1.0 + 0.5 * elongation / 100.0
    assert presets["elastosil-m4601"].tensile_strength_kpa == 6500.0
    assert presets["elastosil-m4601"].elongation_at_break_pct == 700
    assert presets["sylgard-184"].elongation_at_break_pct == 140
    for p in presets.values():
        assert p.source and p.rule and (p.law_params is None or p.law_source)


@pytest.mark.parametrize("name", sorted(SMOOTH_ON))
def test_the_modulus_fit_passes_through_the_datasheet_point(name):
    """The neo-Hookean fit's nominal stress at 100 % elongation (stretch 2) is the datasheet's 100 % modulus."""
    p = material_presets()[name]
    law = p.law()
    assert law is not None
    stretch = 2.0
    nominal = law.mu_kpa * (stretch - stretch**-2)
    np.testing.assert_allclose(nominal, p.modulus_100_kpa, rtol=1e-12)


def test_materials_command_text_json_and_help():
    text = runner.invoke(app, ["materials"])
    assert text.exit_code == 0 and "ecoflex-00-30: Shore 00-30" in text.output and "source:" in text.output
    out = runner.invoke(app, ["materials", "--json"])
    assert out.exit_code == 0
    names = [m["name"] for m in json.loads(out.output)["materials"]]
    assert names == list(material_presets())
    assert runner.invoke(app, ["materials", "--help"]).exit_code == 0


def test_a_custom_material_is_used_and_an_incomplete_one_refused(tmp_path):
    law = {"kind": "yeoh", "c1_kpa": 12.0, "c2_kpa": 0.5, "c3_kpa": 0.0}
    full = {"name": "lab-silicone", "shore": "00-35", "tensile_strength_mpa": 1.2, "elongation_at_break_pct": 700,
            "law": law, "source": "our tensile tests, report 7, table 2"}
    good = write_case(tmp_path, "good", final={"centerline": "c.vtp", "surface": "s.stl"}, material={"custom": full})
    from softdesign.config import load_case

    limits = load_case(good).material.limits()
    assert (limits.name, limits.max_stretch) == ("lab-silicone", 4.5)
    partial = {k: v for k, v in full.items() if k != "tensile_strength_mpa"}
    bad = write_case(tmp_path, "bad", final={"centerline": "c.vtp", "surface": "s.stl"}, material={"custom": partial})
    result = runner.invoke(app, ["validate", str(bad)])
    assert result.exit_code == 2 and "tensile_strength_mpa" in result.output
    both = write_case(tmp_path, "both", final={"centerline": "c.vtp", "surface": "s.stl"},
                      material={"name": "ecoflex-00-30", "custom": full})
    result = runner.invoke(app, ["validate", str(both)])
    assert result.exit_code == 2 and "not both" in result.output
