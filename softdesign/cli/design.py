"""`softdesign design CASE.yaml [--tolerance-mm T]`: the design stage's command line (issue 30).

The stage (:mod:`softdesign.pipeline.stages.design`, the core
:mod:`softdesign.kinematics.chain_design`) composes constant-curvature
sections from the base frame; here the options are put over the case's
``design:`` block, the stage runs (cached), the result is printed, and a
case file that builds the designed actuator (``blend: pcc``) is written.
:mod:`softdesign.cli` registers the command.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from softdesign.cli.common import (
    TEXT_ANGLES,
    CaseArg,
    JsonOpt,
    OutOpt,
    ReplaceOpt,
    case_inputs,
    check_output_file,
    emit_json,
    note,
    run_guarded,
)
from softdesign.errors import ConfigError, SoftdesignError
from softdesign.limits.design import MAX_DESIGN_LINKS

if TYPE_CHECKING:  # numpy is imported where it is used: `softdesign --help` starts without it
    import numpy as np

    from softdesign.config import Case


class DesignFailed(SoftdesignError):
    """No chain within --max-links meets the bounds (exit 1)."""


def _checked_options(tolerance_mm: float | None, min_link_mm: float | None, max_links: int | None,
                     tip_mm: float | None, tip_deg: float | None) -> None:
    for flag, value, unit in (("--tolerance-mm", tolerance_mm, " mm"), ("--tip-tolerance-mm", tip_mm, " mm"),
                              ("--tip-tolerance-deg", tip_deg, " degrees")):
        if value is not None and not (math.isfinite(value) and value > 0.0):
            raise ConfigError(f"{flag} must be a finite number > 0{unit}, got {value:g}; e.g. {flag} 1")
    if min_link_mm is not None and not (math.isfinite(min_link_mm) and min_link_mm > 0.0):
        raise ConfigError(f"--min-link-mm must be a finite number > 0 mm, got {min_link_mm:g}; or leave it out "
                          "for the vessel's median diameter")
    if max_links is not None and not 1 <= max_links <= MAX_DESIGN_LINKS:
        raise ConfigError(f"--max-links must be 1 to {MAX_DESIGN_LINKS}, got {max_links}")


def _case_with_design(case_file: Path, options: dict[str, Any]) -> Case:
    """The case with the command line's options put over its ``design:`` block (checked as the case file is)."""
    from pydantic import ValidationError

    from softdesign.config import load_case
    from softdesign.config.design import Design

    case = load_case(case_file)
    given = {k: v for k, v in options.items() if v is not None}
    if case.design is None and "tolerance_mm" not in given:
        raise ConfigError(f"{case_file}: no design: block and no --tolerance-mm; give --tolerance-mm T (mm)")
    base = case.design.model_dump() if case.design is not None else {}
    try:
        design = Design.model_validate({**base, **given})
    except ValidationError as err:
        first = err.errors()[0]
        flag = "--" + str(first["loc"][0]).replace("_", "-")
        raise ConfigError(f"{flag}: {first['msg']}, got {first.get('input')!r}") from None
    return case.model_copy(update={"design": design})


def _print(document: dict[str, Any], case_file: Path, chambers: np.ndarray | None) -> None:
    verdict = "within" if document["meets_tolerance"] else "NOT within"
    typer.echo(f"{case_file}: {len(document['links'])} section(s) composed from the base frame, {verdict} the bounds: "
               f"chain {document['chain_max_deviation_mm']:.4g} mm from the centerline (tolerance "
               f"{document['tolerance_mm']:g} mm), tip {document['tip_error_mm']:.4g} mm (tolerance "
               f"{document['tip_tolerance_mm']:g} mm) and {document['tip_error_deg']:.4g} deg")
    typer.echo(f"{'link':>4}  {'l range':>13}  {'kappa [1/mm]':>12}  {'phi [deg]':>9}  {'L [mm]':>8}  "
               f"{'theta [deg]':>11}  {'max dev [mm]':>12}  {'chambers l1 l2 l3 [mm]':>24}")
    for j, k in enumerate(document["links"]):
        cells = "-" if chambers is None else " ".join(f"{v:7.3f}" for v in chambers[j])
        typer.echo(f"{k['index']:>4}  {k['l_start']:6.4f}-{k['l_end']:6.4f}  {k['kappa']:12.6f}  "
                   f"{math.degrees(k['phi']):9.3f}  {k['length']:8.3f}  {math.degrees(k['theta']):11.3f}  "
                   f"{k['max_deviation_mm']:12.4g}  "
                   f"{cells:>24}")
    typer.echo(f"breaks l = {[round(b, 6) for b in document['breaks']]}")
    typer.echo(f"{TEXT_ANGLES}; phi from the section's base N towards B; " + document["method"])


def design(
    case_file: CaseArg,
    tolerance_mm: Annotated[float | None, typer.Option(
        "--tolerance-mm", help="Largest distance between the composed chain and the centerline, both ways, mm "
        "[default: the case's design.tolerance_mm].", show_default=False)] = None,
    tip_tolerance_mm: Annotated[float | None, typer.Option(
        "--tip-tolerance-mm", help="Largest tip position error, mm [default: the tolerance].")] = None,
    tip_tolerance_deg: Annotated[float | None, typer.Option(
        "--tip-tolerance-deg", help="Largest angle between the tip tangents, degrees [default: none].")] = None,
    d: Annotated[str | None, typer.Option("--d", help='Chamber distance from the backbone, mm, for the chamber '
                                          'lengths: one value ("4") or one per designed section.')] = None,
    max_links: Annotated[int | None, typer.Option(
        "--max-links", help=f"Most sections (1 to {MAX_DESIGN_LINKS}) [default: 20].")] = None,
    min_link_mm: Annotated[float | None, typer.Option(
        "--min-link-mm", help="Shortest section, mm [default: the vessel's median diameter].")] = None,
    output: Annotated[Path | None, typer.Option(
        "--output", help="The designed case file to write [default: <case>-designed.yaml beside the case].")] = None,
    json_out: JsonOpt = False,
    out: OutOpt = None,
    force: ReplaceOpt = False,
) -> None:
    """The fewest constant-curvature sections, composed from the base frame, within the bounds of the centerline.

    Runs the build's design stage (cached) with these options over the case's
    design: block: section 1 starts on the centerline's base frame, each next
    one on the previous tip; the chain's largest true distance from the q = 1
    centerline (both ways, the tip included) must be within --tolerance-mm,
    its tip within --tip-tolerance-mm (and --tip-tolerance-deg).  Writes a
    case file with that design: block, blend: pcc and the design's link
    breaks, which builds the designed actuator.  Exit 1, with the best chain
    and its error, when none within --max-links meets the bounds; nothing is
    written then.  JSON (also BUILD/design/summary.json): {"tolerance_mm",
    "tip_tolerance_mm", "tip_tolerance_deg", "min_link_mm", "max_links",
    "meets_tolerance", "chain_max_deviation_mm", "tip_error_mm",
    "tip_error_deg", "base_frame" (4x4), "links": [{"index", "l_start",
    "l_end", "kappa", "phi", "length", "theta", "dh" (Zou et al.'s five D-H
    rows {"theta", "d", "a", "alpha"}), "tip_frame" (4x4),
    "max_deviation_mm", "chamber_lengths"}], "breaks", "searched", "method",
    "convention", "dh_convention"}; mm and radians, degrees only in keys
    ending _deg.
    """

    def action() -> None:
        from softdesign.cli.pcc_options import spacing_from_text
        from softdesign.pipeline.api import build_through

        _checked_options(tolerance_mm, min_link_mm, max_links, tip_tolerance_mm, tip_tolerance_deg)
        if d is not None:
            spacing_from_text(d, None)  # numbers > 0: fail before building
        target = output if output is not None else case_file.with_name(f"{case_file.stem}-designed.yaml")
        if target.is_dir():
            raise ConfigError(f"--output {target}: is a folder, expected the case file to write; name a file in it, "
                              f"e.g. {target / (case_file.stem + '-designed.yaml')}")
        if target.resolve() == case_file.resolve():
            raise ConfigError(f"--output {target}: is the case file itself; write the design to another file")
        check_output_file("--output", target, force, case_inputs(case_file))
        case = _case_with_design(case_file, {
            "tolerance_mm": tolerance_mm, "tip_tolerance_mm": tip_tolerance_mm,
            "tip_tolerance_deg": tip_tolerance_deg, "max_links": max_links, "min_link_mm": min_link_mm})
        outcome = build_through(case_file, out, target="design", progress=note, case=case)
        document = dict(outcome.results["design"].document)
        chambers = None if d is None else _chamber_lengths(document["links"], d)
        document["links"] = [{**k, "chamber_lengths": None if chambers is None else chambers[j].tolist()}
                             for j, k in enumerate(document["links"])]
        if json_out:
            emit_json(document)
        else:
            _print(document, case_file, chambers)
        if not document["meets_tolerance"]:
            from softdesign.pipeline.stages.design import miss_text

            raise DesignFailed(f"{case_file}: {miss_text(document)} (above); nothing written")
        _write_case(case_file, target, document["breaks"], case, outcome.case.name)

    run_guarded(action)


def _chamber_lengths(links: list[dict[str, Any]], d: str) -> np.ndarray:
    """(links, 3) mm, Zou et al.'s inverse (``pcc.lengths_from_arcs``) per designed arc; a note for a chamber <= 0."""
    import numpy as np

    from softdesign.cli.pcc_options import spacing_from_text
    from softdesign.kinematics import pcc

    count = len(links)
    spacing = spacing_from_text(d, count, where=f"the design ({count} sections)")
    kappa, phi, length = (np.array([k[name] for k in links]) for name in ("kappa", "phi", "length"))
    chambers = pcc.lengths_from_arcs(kappa, phi, length, spacing)
    for j in np.flatnonzero(~np.all(chambers > 0.0, axis=1)):
        note(f"warning: section {j}: a chamber would be <= 0 mm long (kappa d = "
             f"{kappa[j] * spacing[j]:.3g} >= 1); use d < {1.0 / kappa[j]:.3g} mm")
    return chambers


def _write_case(case_file: Path, target: Path, breaks: list[float], case: Case, name: str) -> None:
    """The case file's text with the design: block used, blend: pcc and the design's breaks (the rest kept)."""
    from softdesign.io.atomic import write_bytes_atomically
    from softdesign.io.case_edit import breaks_text, case_text_with_keys, rounded_breaks
    from softdesign.io.case_yaml import read_case_text

    assert case.design is not None
    block = {k: v for k, v in case.design.model_dump().items() if v is not None}
    flow = "{" + ", ".join(f"{k}: {v!r}" for k, v in block.items()) + "}"
    updates: dict[str, tuple[Any, str]] = {"design": (block, flow), "blend": ("pcc", "pcc"),
                                           "links": ({"breaks": rounded_breaks(breaks)}, breaks_text(breaks))}
    from softdesign.config.design import pcc_blend_problems

    problems = pcc_blend_problems("pcc", case.design, case.initial.kind, len(case.intermediate))
    if problems:  # the case's own q = 0 shape or keyframes: keep its blend, say why
        del updates["blend"]
        note(f"note: {target} keeps blend: {case.blend}: " + "; ".join(problems))
    text = read_case_text(case_file)
    new_text, kept = case_text_with_keys(text, updates, case_file.parent, target.parent, case_file)
    try:
        write_bytes_atomically(target, new_text.encode("utf-8"))
    except OSError as err:
        raise ConfigError(f"--output {target}: cannot write it ({err.strerror or err}); choose a writable path"
                          ) from None
    blend = "blend: pcc, " if "blend" in updates else ""
    note(f"wrote {target} (design: {flow}, {blend}links: the design's breaks)")
    if not kept:
        note(f"note: {target} was written whole from the parsed case (its comments are not kept): the text "
             "edit could not be checked on this YAML")
    note(f"note: it keeps name: {name}, so `softdesign build {target}` builds into build/{name} unless given --out")
