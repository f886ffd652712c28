"""`softdesign materials [--json]`: the material presets, each datasheet value with its source, law and limits."""

from __future__ import annotations

import typer

from softdesign.cli.common import JsonOpt, emit_json, run_guarded


def materials(as_json: JsonOpt = False) -> None:
    """List the material presets (softdesign/data/materials.yaml): datasheet values, sources, laws and limits."""

    def action() -> None:
        from softdesign.materials.data import material_presets

        presets = [p.as_dict() for p in material_presets().values()]
        if as_json:
            emit_json({"materials": presets})
            return
        for p in presets:
            law = p["law"]
            law_text = "no law" if law is None else (f"{law['kind']} C1 {law['c1_kpa']:g} kPa" + (
                "" if law["kind"] == "neo-hookean" else f", C2 {law['c2_kpa']:g}, C3 {law['c3_kpa']:g} kPa"))
            tensile = "-" if p["tensile_strength_kpa"] is None else f"{p['tensile_strength_kpa'] / 1000:.3g} MPa"
            modulus = "-" if p["modulus_100_kpa"] is None else f"{p['modulus_100_kpa']:.1f} kPa"
            typer.echo(f"{p['name']}: Shore {p['shore']}, tensile strength {tensile}, 100 % modulus {modulus}, "
                       f"elongation at break {p['elongation_at_break_pct']:g} %; {law_text}; max_stretch "
                       f"{p['max_stretch']:g}, min_stretch {p['min_stretch']:g}, min_wall_mm {p['min_wall_mm']:g}")
            typer.echo(f"  source: {p['source']}{'' if p['checked'] else ' [not checked against the document]'}")
            if law is not None:
                typer.echo(f"  law: {law['source']}")
            typer.echo(f"  rule: {p['rule']}")

    run_guarded(action)
