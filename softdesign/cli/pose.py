"""`softdesign pose CASE.yaml --q Q -o FILE`: the body with one q per link, checked and written.

Parsing, the build folder, files and printing live here; the geometry is
:mod:`softdesign.meshing.body.pose`.  :mod:`softdesign.cli` registers the
command with ``app.command()(pose)``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Any

import typer

from softdesign.cli.common import (
    Q_FIX,
    CaseArg,
    JsonOpt,
    OutOpt,
    QOpt,
    case_inputs,
    check_output_file,
    emit_json,
    note,
    q_values_from_text,
    run_guarded,
)
from softdesign.errors import ConfigError, errors_named_for
from softdesign.io.format_names import MESH_FORMATS

OutputOpt = Annotated[
    Path,
    typer.Option("--output", help="Mesh file to write; its suffix picks the format ("
                 + " ".join(f".{f}" for f in MESH_FORMATS) + ").", show_default=False),
]


PoseForceOpt = Annotated[bool, typer.Option(
    "--force", help="Redo every stage, ignoring the cache, and replace the --output file if it exists.")]


def mesh_format_of(path: Path) -> str:
    """The mesh format named by ``path``'s suffix; ConfigError for an unknown one or a missing folder."""
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in MESH_FORMATS:
        raise ConfigError(
            f"--output {path}: unknown mesh format '{path.suffix or '(no suffix)'}', expected one of "
            + ", ".join(f".{f}" for f in MESH_FORMATS)
            + "; name the file e.g. pose.stl"
        )
    if not path.parent.is_dir():
        raise ConfigError(f"--output {path}: the folder {path.parent} does not exist; create it first")
    return fmt


def _check_build_folder_option(out: Path | None) -> None:
    """``--out/-o`` is the build folder in every command: a mesh file name there is a mistake, say so."""
    if out is not None and out.suffix.lower().lstrip(".") in MESH_FORMATS:
        raise ConfigError(
            f"--out/-o {out}: is the build folder in every softdesign command, not the mesh file; "
            f"write the mesh with --output {out} (and give --out a folder, or leave it out for build/<name>)"
        )


def pose_payload(body: Any, output: Path) -> dict[str, Any]:
    """The JSON object of ``pose``: q, each link's {S} in world, each joint's step, the solid's figures."""
    report = body.report
    return {
        "q": body.q.tolist(),
        "output": str(output),
        "links": [
            {"index": k.index, "q": k.q, "l_start": k.l_start, "l_end": k.l_end, "length": k.length_mm,
             "start_to_world": (k.start2world + 0.0).tolist(), "volume_mm3": k.volume_expected}
            for k in body.links
        ],
        "joints": [
            {"index": j.index, "l": j.l, "max_step_mm": j.max_step_mm, "shared_vertices": j.shared_vertices,
             "crossings": j.crossings, "annulus_faces": j.annulus_faces, "annulus_area_mm2": j.annulus_area_mm2,
             "min_wall_mm": j.min_wall_mm}
            for j in body.joints
        ],
        "kind": body.kind,
        "volume_mm3": report.volume,
        "volume_expected_mm3": report.volume_expected,
        "volume_rel_error": report.volume_rel_error,
        "area_mm2": report.area,
        "vertices": report.vertices,
        "faces": report.faces,
        "watertight": report.watertight,
        "winding_consistent": report.winding_consistent,
        "bodies": report.bodies,
        "max_rho_kappa": body.max_rho_kappa,
    }


def _print_pose(payload: dict[str, Any], seconds: float) -> None:
    typer.echo("q = [" + ", ".join(f"{v:g}" for v in payload["q"]) + f"] ({len(payload['links'])} links)")
    for k in payload["links"]:
        x, y, z = (row[3] for row in k["start_to_world"][:3])
        typer.echo(
            f"link {k['index']}: q {k['q']:.3f}, l {k['l_start']:.3f}..{k['l_end']:.3f}, length {k['length']:.3f} mm, "
            f"{{S}} at ({x:.3f}, {y:.3f}, {z:.3f}) mm"
        )
    for j in payload["joints"]:
        where = f"joint {j['index']}|{j['index'] + 1} at l {j['l']:.3f}:"
        if j["annulus_faces"] == 0:
            typer.echo(f"{where} rings shared (no radial step)")
            continue
        typer.echo(
            f"{where} radial step up to {j['max_step_mm']:.4f} mm, closed by an annulus of {j['annulus_faces']} "
            f"faces ({j['annulus_area_mm2']:.3f} mm2, {j['crossings']} crossing(s), "
            f"{j['shared_vertices']} shared vertices)"
            + (f", thinnest wall {j['min_wall_mm']:.3f} mm" if j["min_wall_mm"] is not None else "")
        )
    typer.echo(
        f"{payload['kind']} body: volume {payload['volume_mm3']:.2f} mm3 "
        f"({100 * payload['volume_rel_error']:+.3f}% vs the links' integral "
        f"{payload['volume_expected_mm3']:.2f} mm3), area {payload['area_mm2']:.2f} mm2, {payload['faces']} faces, "
        f"{'watertight' if payload['watertight'] else 'NOT watertight'}, {payload['bodies']} body, "
        f"max rho*kappa {payload['max_rho_kappa']:.3f}"
    )
    typer.echo(f"wrote {payload['output']} ({seconds:.2f} s)")


def _make_pose(case_file: Path, q: list[float], out: Path | None, force: bool) -> Any:
    """Build (cached) through every stage, then the pose body; errors name the case file."""
    from softdesign.meshing.body.pose import PoseSpec, pose_body
    from softdesign.meshing.end_cut import end_cuts_from_record
    from softdesign.pipeline.api import build_through

    outcome = build_through(case_file, out, None, force, progress=note)
    chain, field = outcome.results["kinematics"].chain, outcome.results["fit"].field
    if len(q) not in (1, chain.count):
        raise ConfigError(f"--q: {len(q)} values for {chain.count} links in {case_file}; {Q_FIX}")
    export = outcome.case.export
    with errors_named_for(case_file):
        spec = PoseSpec(export.spacing_mm, export.angular_count, export.offset_mm, export.wall_mm or 0.0,
                        export.port_mm or 0.0, end_cuts_from_record(outcome.results["fit"].summary.get("end_cut")))
        return pose_body(chain, field, q, spec)


def pose(
    case_file: CaseArg,
    q: QOpt,
    output: OutputOpt,
    out: OutOpt = None,
    force: PoseForceOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """The body with one q per link (each link's surface at its own q, placed by the links before it).

    The solid is the export's: offset, or hollow with a port when the case's export section asks.
    """

    def action() -> None:
        from softdesign.io.formats import write_mesh

        start = time.perf_counter()
        _check_build_folder_option(out)
        q_values = q_values_from_text(q)
        mesh_format_of(output)  # refuse an unknown suffix or folder before the build, not after
        check_output_file("--output", output, force, case_inputs(case_file))
        body = _make_pose(case_file, q_values, out, force)
        try:
            write_mesh(output, body.vertices, body.faces, body.regions)
        except OSError as err:
            raise ConfigError(
                f"--output {output}: cannot write the mesh ({err.strerror}); choose a writable path"
            ) from err
        payload = pose_payload(body, output)
        if as_json:
            emit_json(payload)
        else:
            _print_pose(payload, time.perf_counter() - start)

    run_guarded(action)
