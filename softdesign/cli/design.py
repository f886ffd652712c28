"""`softdesign design CASE.yaml --tolerance-mm T`: the fewest links whose constant-curvature arcs reach the shape.

Parsing, the build folder, the written case file and printing live here; the
segmentation is :mod:`softdesign.kinematics.arc_design` and the case-file edit
:mod:`softdesign.io.case_edit`.  :mod:`softdesign.cli` registers the command.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from softdesign.cli.common import (
    CaseArg,
    JsonOpt,
    OutOpt,
    case_inputs,
    emit_json,
    note,
    refuse_overwriting_inputs,
    run_guarded,
)
from softdesign.errors import ConfigError, SoftdesignError, errors_named_for

if TYPE_CHECKING:  # numpy is imported where it is used: `softdesign --help` starts without it
    import numpy as np

#: Most links a user may ask for (a bound on the minimax programme's levels, each n^2).
MAX_LINKS_LIMIT = 200

CONVENTION = (
    "Centerline at q = 1, sampled at the resampled points (the candidate breaks); each link's arc starts at the link's "
    "start frame F(l_start) = [N B T c] (rotation-minimizing, whatever frames: says), tangent to T, phi (rad) from "
    "N towards B, bending towards phi (seed 003); "
    "max_deviation_mm is the largest true distance from the link's samples to its arc; the arcs are chained by "
    "seed 003's improved D-H from the base frame and tip_error_mm / tip_error_rad are the position and rotation angle "
    "between the chain's tip frame and the centerline's tip frame inv(F(0)) F(1); chamber_lengths (mm) at 90, 210, "
    "330 degrees from N, d mm from the backbone (null without --d); breaks are normalized l of the final shape"
)


class DesignFailed(SoftdesignError):
    """No segmentation within --max-links meets the tolerance (exit 1)."""


def _checked_options(tolerance_mm: float, min_link_mm: float | None, max_links: int | None) -> None:
    if not (math.isfinite(tolerance_mm) and tolerance_mm > 0.0):
        raise ConfigError(f"--tolerance-mm must be a finite number > 0 mm, got {tolerance_mm:g}; e.g. --tolerance-mm 1")
    if min_link_mm is not None and not (math.isfinite(min_link_mm) and min_link_mm > 0.0):
        raise ConfigError(f"--min-link-mm must be a finite number > 0 mm, got {min_link_mm:g}; or leave it out "
                          "for the vessel's median diameter")
    if max_links is not None and not 1 <= max_links <= MAX_LINKS_LIMIT:
        raise ConfigError(f"--max-links must be 1 to {MAX_LINKS_LIMIT}, got {max_links}")


def _median_diameter(radius: np.ndarray | None, case_file: Path) -> float:
    import numpy as np

    if radius is None or not len(radius):
        raise ConfigError(
            f"{case_file}: the centerline carries no radius (MaximumInscribedSphereRadius), so the default shortest "
            "link (the vessel's median diameter) is unknown; give --min-link-mm"
        )
    return float(2.0 * np.median(radius))


def _document(design: Any, l_grid: np.ndarray, tolerance_mm: float, chambers: np.ndarray | None) -> dict[str, Any]:
    from softdesign.io.case_edit import rounded_breaks

    links = []
    for j, link in enumerate(design.links):
        links.append({
            "index": j,
            "l_start": float(l_grid[link.start]),
            "l_end": float(l_grid[link.end]),
            "kappa": link.kappa,
            "phi": link.phi,
            "length": link.length,
            "theta": link.theta,
            "max_deviation_mm": link.max_deviation_mm,
            "chamber_lengths": None if chambers is None else chambers[j].tolist(),
        })
    return {
        "tolerance_mm": tolerance_mm,
        "meets_tolerance": design.meets_tolerance,
        "worst_deviation_mm": design.worst_mm,
        "links": links,
        "breaks": rounded_breaks([float(l_grid[i]) for i in design.break_indices]),
        "tip_error_mm": design.tip_error_mm,
        "tip_error_rad": design.tip_error_rad,
        "convention": CONVENTION,
    }


def _print(document: dict[str, Any], case_file: Path, min_link_mm: float) -> None:
    verdict = "within" if document["meets_tolerance"] else "NOT within"
    typer.echo(f"{case_file}: {len(document['links'])} link(s), each {verdict} {document['tolerance_mm']:g} mm of one "
               f"constant-curvature arc (links >= {min_link_mm:.3g} mm)")
    typer.echo(f"{'link':>4}  {'l range':>13}  {'kappa [1/mm]':>12}  {'phi [deg]':>9}  {'L [mm]':>8}  {'theta':>7}  "
               f"{'max dev [mm]':>12}  {'chambers l1 l2 l3 [mm]':>24}")
    for k in document["links"]:
        chambers = "-" if k["chamber_lengths"] is None else " ".join(f"{v:7.3f}" for v in k["chamber_lengths"])
        typer.echo(f"{k['index']:>4}  {k['l_start']:6.4f}-{k['l_end']:6.4f}  {k['kappa']:12.6f}  "
                   f"{math.degrees(k['phi']):9.3f}  {k['length']:8.3f}  {k['theta']:7.4f}  "
                   f"{k['max_deviation_mm']:12.4g}  {chambers:>24}")
    typer.echo(f"breaks l = {document['breaks']}")
    typer.echo(f"worst link deviation {document['worst_deviation_mm']:.4g} mm; tip of the chained arcs off by "
               f"{document['tip_error_mm']:.4g} mm and {document['tip_error_rad']:.4g} rad")


def design(
    case_file: CaseArg,
    tolerance_mm: Annotated[float, typer.Option("--tolerance-mm", help="Largest distance of a link from its arc, mm.",
                                                show_default=False)],
    d: Annotated[str | None, typer.Option("--d", help='Chamber distance from the backbone, mm, for the chamber '
                                          'lengths: one value ("4") or one per designed link.')] = None,
    max_links: Annotated[int | None, typer.Option("--max-links", help=f"Most links (1 to {MAX_LINKS_LIMIT}).")] = None,
    min_link_mm: Annotated[float | None, typer.Option(
        "--min-link-mm", help="Shortest link, mm [default: the vessel's median diameter].")] = None,
    output: Annotated[Path | None, typer.Option(
        "--output", help="The designed case file to write [default: <case>-designed.yaml beside the case].")] = None,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """The fewest links, each within --tolerance-mm of one constant-curvature arc, and a case file that builds them.

    Runs the build through blend (cached), then splits the q = 1 centerline at
    its resampled points by an exact dynamic programme: the fewest links of at
    least --min-link-mm whose largest true point-to-arc distance is within the
    tolerance, and among those the smallest worst distance.  Reports each
    link's arc (kappa, phi, L, theta) and deviation, the tip error of the arcs
    chained by seed 003's improved D-H, and with --d the chamber lengths.
    Writes the case file with links: {breaks: [...]} (the rest of its text
    kept).  Exit 1, with the best segmentation within --max-links and its
    error, when none meets the tolerance; nothing is written then.  JSON:
    {"tolerance_mm", "meets_tolerance", "worst_deviation_mm", "links":
    [{"index", "l_start", "l_end", "kappa", "phi", "length", "theta",
    "max_deviation_mm", "chamber_lengths"}], "breaks", "tip_error_mm",
    "tip_error_rad", "convention"}.
    """

    def action() -> None:
        from softdesign.cli.pcc_options import spacing_from_text
        from softdesign.kinematics.arc_check import final_shape_rmf
        from softdesign.kinematics.arc_design import DesignOptions, design_links
        from softdesign.pipeline.api import build_through

        _checked_options(tolerance_mm, min_link_mm, max_links)
        if d is not None:
            spacing_from_text(d, None)  # numbers > 0: fail before building
        target = output if output is not None else case_file.with_name(f"{case_file.stem}-designed.yaml")
        if not target.parent.is_dir():
            raise ConfigError(f"--output {target}: the folder {target.parent} does not exist; create it first")
        if target.is_dir():
            raise ConfigError(f"--output {target}: is a folder, expected the case file to write; name a file in it, "
                              f"e.g. {target / (case_file.stem + '-designed.yaml')}")
        if target.resolve() == case_file.resolve():
            raise ConfigError(f"--output {target}: is the case file itself; write the design to another file")
        refuse_overwriting_inputs("--output", target, case_inputs(case_file))
        outcome = build_through(case_file, out, target="blend", progress=note)
        shape = outcome.results["blend"].shape
        curve = final_shape_rmf(shape)
        l_grid = shape.smooth_curve_at(1.0).l_grid
        shortest = min_link_mm if min_link_mm is not None else _median_diameter(
            outcome.results["ingest"].path.radius, case_file)
        links_cap = max_links if max_links is not None else MAX_LINKS_LIMIT
        options = DesignOptions(tolerance_mm, shortest, min(links_cap, len(l_grid) - 1))
        with errors_named_for(case_file):
            result = design_links(curve.points(l_grid), curve.frames(l_grid), curve.curve.arc_length(l_grid), options)
        chambers = None if d is None else _chamber_lengths(result, d)
        document = _document(result, l_grid, tolerance_mm, chambers)
        if json_out:
            emit_json(document)
        else:
            _print(document, case_file, shortest)
        if not result.meets_tolerance:
            raise DesignFailed(
                f"{case_file}: no segmentation into at most {options.max_links} link(s) of at least {shortest:.3g} mm "
                f"keeps every link within {tolerance_mm:g} mm of one arc; the best has {len(result.links)} link(s) "
                f"and misses by up to {result.worst_mm:.4g} mm (above); nothing written. Raise --tolerance-mm or "
                "--max-links, or lower --min-link-mm"
            )
        _write_case(case_file, target, document["breaks"], outcome.case.name)

    run_guarded(action)


def _chamber_lengths(result: Any, d: str) -> np.ndarray:
    """(links, 3) mm, seed 003's inverse (``pcc.lengths_from_arcs``) per designed arc; a note for a chamber <= 0."""
    import numpy as np

    from softdesign.cli.pcc_options import spacing_from_text
    from softdesign.kinematics import pcc

    count = len(result.links)
    spacing = spacing_from_text(d, count, where=f"the design ({count} links)")
    kappa, phi, length = (np.array([getattr(k, name) for k in result.links]) for name in ("kappa", "phi", "length"))
    chambers = pcc.lengths_from_arcs(kappa, phi, length, spacing)
    for j in np.flatnonzero(~np.all(chambers > 0.0, axis=1)):
        note(f"warning: link {j}: a chamber would be <= 0 mm long (kappa d = "
             f"{result.links[j].kappa * spacing[j]:.3g} >= 1); use d < {1.0 / result.links[j].kappa:.3g} mm")
    return chambers


def _write_case(case_file: Path, target: Path, breaks: list[float], name: str) -> None:
    from softdesign.io.atomic import write_bytes_atomically
    from softdesign.io.case_edit import case_text_with_breaks

    text = case_file.read_text(encoding="utf-8")
    new_text, kept = case_text_with_breaks(text, breaks, case_file.parent, target.parent)
    try:
        write_bytes_atomically(target, new_text.encode("utf-8"))
    except OSError as err:
        raise ConfigError(f"--output {target}: cannot write it ({err.strerror or err}); choose a writable path"
                          ) from None
    note(f"wrote {target} (links: breaks of the design)")
    if not kept:
        note(f"note: {target} was written whole from the parsed case (its comments are not kept): the text "
             "edit could not be checked on this YAML")
    note(f"note: it keeps name: {name}, so `softdesign build {target}` builds into build/{name} unless given --out")
