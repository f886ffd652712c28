"""`softdesign centerline SURFACE`: VMTK-style centerlines from a vessel surface alone (softdesign.centerline)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Any, Literal

import typer

from softdesign.cli.common import JsonOpt, ReplaceOpt, check_output_file, emit_json, note, point_from_text, run_guarded
from softdesign.errors import ConfigError

SurfaceArg = Annotated[
    Path, typer.Argument(help="The vessel surface (.stl .ply .obj .vtp .vtk), open at its ends or capped.",
                         show_default=False)
]
UnitsOpt = Annotated[
    str, typer.Option("--units", help="Units of the surface file (mm, cm or m); the output is written in them.")
]
InletOpt = Annotated[
    str | None,
    typer.Option("--inlet", help="x,y,z: the inlet is the opening nearest this point [default: the largest].",
                 show_default=False),
]
OutletOpt = Annotated[
    list[str] | None,
    typer.Option("--outlet", help="x,y,z of an outlet; repeat for each [default: every other opening].",
                 show_default=False),
]
CenterlineOutputOpt = Annotated[Path, typer.Option("--output", help="The centerline file to write (.vtp).")]

UNIT_CHOICES: tuple[Literal["mm", "cm", "m"], ...] = ("mm", "cm", "m")


def centerline(
    surface: SurfaceArg,
    units: UnitsOpt = "mm",
    inlet: InletOpt = None,
    outlet: OutletOpt = None,
    output: CenterlineOutputOpt = Path("centerline.vtp"),
    json: JsonOpt = False,
    force: ReplaceOpt = False,
) -> None:
    """Compute VMTK-style centerlines (one polyline per outlet, MaximumInscribedSphereRadius) from a surface."""

    def action() -> None:
        from softdesign.centerline.extract import CenterlineOptions, extract_centerlines
        from softdesign.centerline.result_checks import check_centerlines
        from softdesign.io.centerline_vtp import read_face_regions, write_centerlines_vtp
        from softdesign.io.surface import read_surface
        from softdesign.types import UNIT_SCALE_TO_MM

        if units not in UNIT_CHOICES:
            raise ConfigError(f"--units {units!r}: expected one of {', '.join(UNIT_CHOICES)}")
        if output.suffix.lower() != ".vtp":
            raise ConfigError(f"--output {output}: expected a .vtp file (VMTK's centerline format), got "
                              f"'{output.suffix or '(no suffix)'}'")
        scale = UNIT_SCALE_TO_MM[units]
        inlet_mm = None if inlet is None else _mm(point_from_text(inlet, "--inlet"), scale)
        outlets_mm = tuple(_mm(point_from_text(text, "--outlet"), scale) for text in outlet or [])
        check_output_file("--output", output, force, [surface])
        options = CenterlineOptions(inlet=inlet_mm, outlets=outlets_mm,
                                    regions=read_face_regions(surface) if surface.is_file() else None)
        start = time.perf_counter()
        vertices, faces = read_surface(surface, scale)
        result = extract_centerlines(vertices, faces, options, str(surface))
        check_centerlines(result.paths, result.radii, vertices, faces, str(surface),
                          result.continued_mm)  # nothing written if meaningless
        try:
            write_centerlines_vtp(output, result, 1.0 / scale)
        except OSError as err:
            raise ConfigError(f"--output {output}: cannot write it ({err.strerror or err}); choose a writable path"
                              ) from err
        payload = _payload(result, output, units, time.perf_counter() - start)
        for line in result.notes:
            note(line)
        if json:
            emit_json(payload)
        else:
            _print(payload)

    run_guarded(action)


def _mm(point: tuple[float, float, float], scale: float):
    import numpy as np

    return np.asarray(point, float) * scale


def _payload(result: Any, output: Path, units: str, seconds: float) -> dict[str, Any]:
    from softdesign.types import UNIT_SCALE_TO_MM

    back = 1.0 / UNIT_SCALE_TO_MM[units]
    return {
        "output": str(output),
        "units": units,
        "endpoints": result.endpoints,
        "inlet": [round(float(v) * back, 6) for v in result.inlet],
        "paths": [
            {
                "centerline_id": k,
                "outlet": [round(float(v) * back, 6) for v in result.outlets[k]],
                "points": int(len(points)),
                "length": round(float(_polyline_length(points)) * back, 6),
                "radius_range": [round(float(radius.min()) * back, 6), round(float(radius.max()) * back, 6)],
                "continued": [round(v * back, 6) for v in result.continued_mm[k]],
                "short_of_opening": [round(v * back, 6) for v in result.short_mm[k]],
            }
            for k, (points, radius) in enumerate(zip(result.paths, result.radii, strict=True))
        ],
        "voronoi_vertices": result.voronoi_vertices,
        "seconds": round(seconds, 3),
    }


def _polyline_length(points) -> float:
    import numpy as np

    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def _short(short: list[float], units: str) -> str:
    """'; the inlet stops 1.2 mm short of its opening's centre' when an end could not reach it (``short`` in units)."""
    parts = [f"the {end} stops {_length(value, units)} short of its opening's centre (the straight run would leave "
             "the surface)" for end, value in zip(("inlet", "outlet"), short, strict=True) if value > 0.0]
    return "; " + "; ".join(parts) if parts else ""


def _length(value: float, units: str) -> str:
    """A length of the payload (in ``units``) (:func:`~softdesign.pipeline.length_text.length_text`)."""
    from softdesign.pipeline.length_text import length_text
    from softdesign.types import UNIT_SCALE_TO_MM

    return length_text(value * UNIT_SCALE_TO_MM[units], units)


def _print(payload: dict[str, Any]) -> None:
    units = payload["units"]
    typer.echo(f"endpoints from {payload['endpoints']}; inlet at {payload['inlet']} {units}")
    for path in payload["paths"]:
        lo, hi = path["radius_range"]
        typer.echo(f"  centerline {path['centerline_id']}: {path['points']} points, {_length(path['length'], units)}, "
                   f"radius {_length(lo, units)} to {_length(hi, units)}, to {path['outlet']} {units}")
        typer.echo(f"    ends continued straight past the Voronoi diagram by {_length(path['continued'][0], units)} "
                   f"(inlet) and {_length(path['continued'][1], units)} (outlet)"
                   + _short(path["short_of_opening"], units))
    typer.echo(f"wrote {payload['output']} ({payload['seconds']:.2f} s)")
