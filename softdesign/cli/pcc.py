"""`softdesign pcc ...`: Zou et al.'s piecewise-constant-curvature model from encoder lengths.

The ``pcc`` command group, with ``forward`` (lengths given) and ``reconstruct``
(a readings CSV); ``design`` (a case file) is :mod:`softdesign.pcc_design_cli`
and the options they share are :mod:`softdesign.pcc_options`.  Parsing, files
and printing live here; the model is :mod:`softdesign.kinematics.pcc`.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, NamedTuple

import typer

from softdesign.cli.common import TEXT_ANGLES, JsonOpt, emit_json, note, refuse_overwriting_inputs, run_guarded
from softdesign.cli.pcc_bounds import (
    MAX_LENGTH_MM,
    MAX_POINTS_PER_SECTION,
    MAX_REJECTED_NOTES,
    MAX_SECTIONS,
    check_backbone_points,
    check_readings_file,
    check_readings_rows,
    check_shapes_dir,
)
from softdesign.cli.pcc_design import design
from softdesign.cli.pcc_options import DOpt, LengthsOpt, lengths_from_text, spacing_from_text
from softdesign.errors import ConfigError, InputDataError
from softdesign.io.atomic import write_bytes_atomically

if TYPE_CHECKING:  # numpy is imported where it is used: `softdesign --help` starts without it
    import numpy as np

CONVENTION = (
    "Encoders at 90, 210, 330 degrees from the section's base x axis, d mm from the backbone; "
    "a section bends towards phi (its shortest cable); z is the tangent at the base; "
    "each section's frame continues from the previous section's tip without twist."
)

#: The group's line in ``softdesign --help`` (its own --help adds the convention).
PCC_SHORT_HELP = "Piecewise constant curvature from three cable-encoder lengths per section (Zou et al.)."

pcc_app = typer.Typer(no_args_is_help=True, help=f"{PCC_SHORT_HELP} {CONVENTION}", rich_markup_mode=None)


def forward_payload(lengths: np.ndarray, d: np.ndarray) -> dict:
    """The JSON object of ``pcc forward``: per-section arcs and transforms, the tip and base-to-tip pose."""
    from softdesign.kinematics import pcc

    arcs = pcc.arcs_from_lengths(lengths, d)
    section2prev = pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length)
    tip2base = pcc.chain_transforms(section2prev)[-1]
    sections = [
        {
            "kappa": float(arcs.kappa[i]),
            "phi": float(arcs.phi[i]),
            "length": float(arcs.length[i]),
            "theta": float(arcs.theta[i]),
            "transform": (section2prev[i] + 0.0).tolist(),  # + 0.0 turns -0.0 into 0.0
            "dh": pcc.dh_rows(float(arcs.kappa[i]), float(arcs.phi[i]), float(arcs.length[i])),
        }
        for i in range(len(lengths))
    ]
    tip2base = tip2base + 0.0
    return {"sections": sections, "tip": tip2base[:3, 3].tolist(), "transform": tip2base.tolist(),
            "dh_convention": pcc.DH_CONVENTION}


def _print_forward(payload: dict) -> None:
    typer.echo(
        f"{'section':>7}  {'kappa [1/mm]':>13}  {'phi [deg]':>9}  {'L [mm]':>10}  {'theta [deg]':>11}"
    )
    for i, s in enumerate(payload["sections"], start=1):
        typer.echo(
            f"{i:>7}  {s['kappa']:>13.6e}  {math.degrees(s['phi']):>9.3f}  "
            f"{s['length']:>10.4f}  {math.degrees(s['theta']):>11.4f}"
        )
    x, y, z = payload["tip"]
    typer.echo(f"tip [mm]: x = {x:.4f}, y = {y:.4f}, z = {z:.4f}")
    typer.echo("base-to-tip transform:")
    for row in payload["transform"]:
        typer.echo("  " + "  ".join(f"{v:>10.6f}" for v in row))
    typer.echo(f"{TEXT_ANGLES}; convention: {CONVENTION}")


@pcc_app.command()
def forward(
    lengths: LengthsOpt,
    d: DOpt,
    json_out: JsonOpt = False,
) -> None:
    """Shape of a chain of sections from encoder lengths: kappa, phi, L, theta per section, and the tip pose.

    JSON: {"sections": [{"kappa" (1/mm), "phi" (rad), "length" (mm), "theta" (rad),
    "transform" (4x4, section tip to previous tip), "dh" (Zou et al.'s Table 1: five rows {"theta", "d", "a",
    "alpha"}, rad and mm, whose D-H links Rz Tz Tx Rx multiply to "transform")}], "tip" [x, y, z] (mm),
    "transform" (4x4, tip to base), "dh_convention"}.
    """

    def action() -> None:
        readings = lengths_from_text(lengths)
        payload = forward_payload(readings, spacing_from_text(d, len(readings)))
        if json_out:
            emit_json(payload)
        else:
            _print_forward(payload)

    run_guarded(action)


class Readings(NamedTuple):
    """Rows of an encoder-readings CSV, screened."""

    times: np.ndarray  #: (n,) s, accepted rows
    lengths: np.ndarray  #: (n, k, 3) mm, accepted rows
    lines: np.ndarray  #: (n,) int, line numbers of the accepted rows in the file
    rejected: list[tuple[int, str, str]]  #: (line, time as written, reason)


def _header_sections(path: Path, header: list[str]) -> int:
    """Number of sections a header declares (time + 3 per section)."""
    fix = "expected a header row: a time column, then 3 length columns per section, e.g. 't,l11,l12,l13,l21,l22,l23'"
    count = len(header)
    if count < 4 or (count - 1) % 3:
        raise InputDataError(f"{path} line 1: the header has {count} column(s); {fix}")
    if (count - 1) // 3 > MAX_SECTIONS:
        raise InputDataError(f"{path} line 1: the header names {(count - 1) // 3} sections, above the bound of "
                             f"{MAX_SECTIONS}; {fix}")
    try:
        float(header[0])
    except ValueError:
        return (count - 1) // 3
    raise InputDataError(f"{path} line 1: the first row is numbers, not a header; {fix}")


def _parse_row(values: list[str], sections: int) -> tuple[float | None, np.ndarray | None, list[str]]:
    """Time and (k, 3) lengths of a data row, or the reasons it is unusable."""
    import numpy as np

    reasons = []
    try:
        time = float(values[0])
        if not math.isfinite(time):
            raise ValueError
    except ValueError:
        time = None
        reasons.append(f"time '{values[0].strip()}' is not a finite number")
    lengths = np.full((sections, 3), np.nan)
    for index, text in enumerate(values[1:]):
        section, cable = divmod(index, 3)
        try:
            value = float(text)
        except ValueError:
            reasons.append(f"section {section + 1} cable {cable + 1}: '{text.strip()}' is not a number")
            continue
        if not (math.isfinite(value) and 0 < value <= MAX_LENGTH_MM):
            reasons.append(f"section {section + 1} cable {cable + 1}: length {value:g} mm is not > 0 and "
                           f"<= {MAX_LENGTH_MM:g}")
        lengths[section, cable] = value
    return time, (None if reasons else lengths), reasons


def _rate_reasons(
    time: float, lengths: np.ndarray, previous: tuple[int, float, np.ndarray], max_rate: float | None
) -> list[str]:
    """Why a row cannot follow the previous accepted row in time (empty when it can)."""
    import numpy as np

    line, last_time, last_lengths = previous
    dt = time - last_time
    if dt <= 0:
        return [f"time {time:g} s is not after the previous accepted row (line {line}, time {last_time:g} s)"]
    if max_rate is None:
        return []
    reasons = []
    rates = np.abs(lengths - last_lengths) / dt
    for section, cable in np.argwhere(rates > max_rate):
        change = lengths[section, cable] - last_lengths[section, cable]
        reasons.append(
            f"section {section + 1} cable {cable + 1} changed {change:+g} mm in {dt:g} s "
            f"({rates[section, cable]:g} mm/s > --max-rate {max_rate:g}) since line {line}"
        )
    return reasons


def read_readings(path: Path, max_rate: float | None = None) -> Readings:
    """Read and screen an encoder-readings CSV; bad rows are rejected with a reason, not fatal.

    Raises
    ------
    InputDataError
        Missing or unreadable file, a bad header, or a row with the wrong number of columns.
    """
    import numpy as np

    check_readings_file(path)
    check_readings_rows(path)
    try:
        rows = [(n, row) for n, row in enumerate(csv.reader(io.StringIO(path.read_text())), start=1) if row]
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise InputDataError(f"{path}: cannot read it as a CSV text file ({err}); save it as plain CSV") from err
    if not rows:
        raise InputDataError(f"{path}: the file is empty; expected a header row and one row per reading")
    sections = _header_sections(path, rows[0][1])
    times: list[float] = []
    accepted: list[np.ndarray] = []
    lines: list[int] = []
    rejected: list[tuple[int, str, str]] = []
    for line, values in rows[1:]:
        if len(values) != 3 * sections + 1:
            raise InputDataError(
                f"{path} line {line}: {len(values)} column(s), expected {3 * sections + 1} as in the header "
                f"(time + 3 lengths for each of {sections} section(s)); fix or remove the row"
            )
        time, lengths, reasons = _parse_row(values, sections)  # time and lengths are None only with reasons
        if time is not None and lengths is not None and accepted:
            reasons = _rate_reasons(time, lengths, (lines[-1], times[-1], accepted[-1]), max_rate)
        if reasons or time is None or lengths is None:
            rejected.append((line, values[0].strip(), "; ".join(reasons)))
            continue
        times.append(time)
        accepted.append(lengths)
        lines.append(line)
    return Readings(
        np.array(times, dtype=np.float64),
        np.array(accepted, dtype=np.float64).reshape(-1, sections, 3),
        np.array(lines, dtype=np.int64),
        rejected,
    )


def _write_text_atomically(path: Path, text: str) -> Path:
    """Write ``text`` under a temporary name beside ``path``, then rename it to ``path``."""
    return write_bytes_atomically(path, text.encode("utf-8"))


def _csv_text(header: list[str], rows: Sequence[Sequence[Any]]) -> str:
    import numpy as np

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([[repr(float(v)) if isinstance(v, (float, np.floating)) else v for v in row] for row in rows])
    return buffer.getvalue()


def _tips_csv(readings: Readings, arcs, tip2base: np.ndarray, first: str = "time") -> str:
    import numpy as np

    sections = readings.lengths.shape[1]
    header = [first, "tip_x", "tip_y", "tip_z"] + [f"r{i}{j}" for i in range(1, 4) for j in range(1, 4)]
    header += [f"{name}_{s}" for s in range(1, sections + 1) for name in ("kappa", "phi", "length", "theta")]
    per_section = np.stack([arcs.kappa, arcs.phi, arcs.length, arcs.theta], axis=-1).reshape(
        len(readings.times), 4 * sections
    )
    table = np.column_stack([readings.times, tip2base[:, :3, 3], tip2base[:, :3, :3].reshape(-1, 9), per_section])
    return _csv_text(header, table.tolist())


def _write_backbones(path: Path, readings: Readings, arcs, points_per_section: int) -> Path:
    import numpy as np

    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.kinematics import pcc

    poses = pcc.sample_backbone_poses(arcs.kappa, arcs.phi, arcs.length, points_per_section)
    arc_length, section = pcc.backbone_arc_lengths(arcs.length, points_per_section)
    count = poses.shape[1]
    point_arrays = {
        "time": [np.full(count, t) for t in readings.times],
        "section": [section + 1.0] * len(readings.times),
        "arc_length": list(arc_length),
        "N": list(poses[:, :, :3, 0]),
        "B": list(poses[:, :, :3, 1]),
        "T": list(poses[:, :, :3, 2]),
    }
    cell_arrays = {"time": readings.times, "line": readings.lines}
    return write_polylines_vtp(path, list(poses[:, :, :3, 3]), point_arrays, cell_arrays)


def _readings_and_arcs(path: Path, d: str | None, max_rate: float | None) -> tuple[Readings, Any, str]:
    """The readings of an encoder CSV (``--d`` required) or of an actuation table, their arcs, the first column."""
    import numpy as np

    from softdesign.io.actuation_table import first_row, is_actuation_header, read_actuation_table
    from softdesign.kinematics import pcc
    from softdesign.kinematics.chamber_lengths import arcs_from_chamber_lengths

    check_readings_file(path)  # the size bound, before either reader
    check_readings_rows(path)
    if is_actuation_header(first_row(path)):
        table = read_actuation_table(path, MAX_LENGTH_MM, MAX_SECTIONS)
        if d is not None:
            given = spacing_from_text(d, table.lengths.shape[1], where=str(path))
            if not np.allclose(given, table.distance_mm, rtol=0.0, atol=1e-9):
                raise ConfigError(f"--d {d} differs from {path}'s distance_mm {table.distance_mm.tolist()}; omit --d "
                                  "(the table carries each section's distance)")
        count = len(table.q)
        readings = Readings(table.q, table.lengths, np.arange(2, count + 2), [])
        return readings, arcs_from_chamber_lengths(table.lengths, table.distance_mm, table.first_angle), "q"
    if d is None:
        raise ConfigError(f"{path}: an encoder-readings CSV needs --d (the cables' distance from the backbone, mm)")
    readings = read_readings(path, max_rate)
    spacing = spacing_from_text(d, readings.lengths.shape[1], where=str(path))
    return readings, pcc.arcs_from_lengths(readings.lengths, spacing), "time"


@pcc_app.command()
def reconstruct(
    readings_csv: Annotated[Path, typer.Argument(help="Encoder readings over time (CSV).", show_default=False)],
    out_dir: Annotated[
        Path,
        typer.Option("--shapes-dir", help="Folder for the reconstructed shapes (created if missing).",
                     show_default=False),
    ],
    max_rate: Annotated[
        float | None, typer.Option("--max-rate", help="Reject a row whose length changes faster than this, mm/s.")
    ] = None,
    points_per_section: Annotated[
        int, typer.Option("--points-per-section", min=2, max=MAX_POINTS_PER_SECTION, help="Backbone samples per arc.")
    ] = 21,
    d: Annotated[
        str | None,
        typer.Option("--d", help='Distance of the cables from the backbone, mm: one value ("15") or one per section '
                     '("15,14,13"); required for readings, taken from the table for a build\'s actuation.csv.',
                     show_default=False),
    ] = None,
) -> None:
    """Backbone and tip pose for every row of an encoder-readings CSV, or every q of a build's actuation.csv.

    READINGS.csv has a header row, then per row a time (first column, s) and
    three lengths (mm) per section, sections in order.  Writes, in SHAPES_DIR:
    tips.csv (time, tip_x/y/z in mm, the tip-to-base rotation r11..r33 row by
    row, and kappa/phi/length/theta per section); backbones.vtp (one file, one
    polyline per accepted row, base to tip, with point arrays time, section,
    arc_length (mm) and the frame axes N, B, T (T the tangent), and cell arrays
    time and line); rejected.csv (line, time, reason).  A row is rejected, and
    reported on stderr, when a length is not a number or not > 0, its time is
    not after the previous accepted row, or (with --max-rate) a cable changed
    faster than MAX_RATE mm/s since the previous accepted row.

    A build's actuation.csv (columns q, section, chamber, angle_deg, distance_mm,
    length_mm, ...) is read as it is: one reading per q (tips.csv's first column
    is then q), each section's chambers at their own angles and distance.
    """

    def action() -> None:
        from softdesign.kinematics import pcc

        if max_rate is not None and not (math.isfinite(max_rate) and max_rate > 0):
            raise ConfigError(
                f"--max-rate must be a finite number > 0 mm/s, got {max_rate:g}; omit it to skip the check"
            )
        readings, arcs, first = _readings_and_arcs(readings_csv, d, max_rate)
        check_backbone_points(str(readings_csv), len(readings.times), readings.lengths.shape[1], points_per_section)
        for line, time, reason in readings.rejected[:MAX_REJECTED_NOTES]:
            note(f"{readings_csv} line {line} (time {time}): rejected: {reason}")
        if len(readings.rejected) > MAX_REJECTED_NOTES:
            note(f"{readings_csv}: {len(readings.rejected) - MAX_REJECTED_NOTES:,} more row(s) rejected; "
                 f"{out_dir / 'rejected.csv'} lists every one with its reason")
        for name in ("tips.csv", "backbones.vtp", "rejected.csv"):  # never over the readings themselves
            refuse_overwriting_inputs("--shapes-dir", out_dir / name, [readings_csv])
        check_shapes_dir(out_dir)
        tip2base = pcc.chain_transforms(pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length))[:, -1]
        written = [
            _write_text_atomically(out_dir / "tips.csv", _tips_csv(readings, arcs, tip2base, first)),
            _write_backbones(out_dir / "backbones.vtp", readings, arcs, points_per_section),
            _write_text_atomically(out_dir / "rejected.csv", _csv_text(["line", "time", "reason"], readings.rejected)),
        ]
        typer.echo(f"{readings_csv}: {len(readings.times)} row(s) accepted, {len(readings.rejected)} rejected")
        for path in written:
            typer.echo(f"wrote {path}")
        if not len(readings.times):
            raise InputDataError(f"{readings_csv}: no row was usable; see {out_dir / 'rejected.csv'} for the reasons")

    run_guarded(action)


# Added last: `pcc --help` lists the commands in the order they are added.
pcc_app.command()(design)
