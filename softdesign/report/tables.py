"""Section 5, the tables: the manifest's key figures, the inputs, the software, and every check.

Every key figure carries the JSON pointer (RFC 6901) of its value in
``manifest.json``; the page writes the pointer and the exact JSON value next
to the rounded text, so a reader (or a test) can trace each number.  Checks
are re-evaluated from the recorded figures against the limits the pipeline
applies (a build that failed one would not have been kept, so a "fail" here
means the folder was altered or a limit changed since).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softdesign.meshing.checks import VOLUME_RTOL
from softdesign.pipeline.store import sha256_file
from softdesign.pipeline.versions import software_versions

#: Euler characteristic each kind of solid must have (see :class:`softdesign.meshing.solids.Solid`).
EULER_BY_KIND = {"solid": 2, "ported": 2, "hollow": 4}
#: A tube folds through itself where rho * kappa reaches this.
FOLD_LIMIT = 1.0
#: Distributions that draw the page, listed after those every build records.
REPORT_PACKAGES = ("matplotlib", "pillow")
#: Significant digits of the figures shown (the exact value is kept beside them).
DIGITS = 6


@dataclass(frozen=True)
class KeyFigure:
    """One manifest value: label, unit, its JSON pointer and the value itself."""

    label: str
    unit: str
    pointer: str
    value: Any


@dataclass(frozen=True)
class Check:
    """One check: what was checked, the figure found, what is required, and whether it holds."""

    subject: str
    name: str
    found: str
    required: str
    passed: bool


def resolve_pointer(document: Any, pointer: str) -> Any:
    """The value at a JSON pointer (``/metrics/fit/rms_mm``, list indices as numbers); KeyError when absent."""
    value = document
    for token in pointer.split("/")[1:]:
        token = token.replace("~1", "/").replace("~0", "~")
        if isinstance(value, list):
            index = int(token)
            if not 0 <= index < len(value):
                raise KeyError(pointer)
            value = value[index]
        elif isinstance(value, dict) and token in value:
            value = value[token]
        else:
            raise KeyError(pointer)
    return value


def format_value(value: Any) -> str:
    """Human text of a figure: yes/no, integers as they are, floats to :data:`DIGITS` significant digits."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return f"{value:.{DIGITS}g}"
    return "-" if value is None else str(value)


#: (pointer, label, unit) of the scalar key figures, in page order; absent ones are left out.
SCALAR_FIGURES = (
    ("/metrics/ingest/centerline/selected_length_mm", "input path length", "mm"),
    ("/metrics/ingest/centerline/selected_points", "input path points", ""),
    ("/metrics/ingest/surface/vertices", "input surface vertices", ""),
    ("/metrics/ingest/surface/faces", "input surface triangles", ""),
    ("/metrics/ingest/surface/capped", "input surface capped (watertight)", ""),
    ("/metrics/blend/final_path/length_mm", "final centerline length (q = 1)", "mm"),
    ("/metrics/blend/initial_length_mm", "initial centerline length (q = 0)", "mm"),
    ("/metrics/blend/final_path/max_curvature_per_mm", "largest curvature at q = 1", "1/mm"),
    ("/metrics/blend/shortening/min_length_mm", "shortest centerline over q", "mm"),
    ("/metrics/blend/shortening/q_at_min", "q of the shortest centerline", ""),
    ("/metrics/kinematics/links", "links", ""),
    ("/metrics/fit/rms_mm", "fit: kept-point RMS distance to the surface", "mm"),
    ("/metrics/fit/p95_mm", "fit: kept-point 95th percentile distance", "mm"),
    ("/metrics/fit/p99_mm", "fit: kept-point 99th percentile distance", "mm"),
    ("/metrics/fit/max_mm", "fit: kept-point largest distance", "mm"),
    ("/metrics/fit/holdout_rms_mm", "fit: hold-out RMS (each fold of the kept points, fitted without it)", "mm"),
    ("/metrics/fit/all_wall/rms_mm", "fit: all-wall RMS distance (the path's own wall, kept or not)", "mm"),
    ("/metrics/fit/points/input", "fit: surface points", ""),
    ("/metrics/fit/points/kept", "fit: points kept", ""),
    ("/metrics/fit/points/other_branch", "fit: excluded, other branch", ""),
    ("/metrics/fit/points/cap", "fit: excluded, cap", ""),
    ("/metrics/fit/points/outlier", "fit: excluded, outlier", ""),
    ("/metrics/fit/joint_value_jump_mm", "fit: largest value jump at a joint", "mm"),
    ("/metrics/fit/joint_slope_jump", "fit: largest slope jump at a joint", ""),
    ("/metrics/fit/max_rho_kappa", "fit: largest rho * kappa at q = 1", ""),
)
#: Per export q in ``metrics.blend.per_q``: (key, label, unit).
PER_Q_FIGURES = (
    ("length_mm", "centerline length", "mm"),
    ("stretch_min", "smallest axial stretch", ""),
    ("stretch_max", "largest axial stretch", ""),
    ("curvature_max_per_mm", "largest curvature", "1/mm"),
)
#: Per mesh in ``outputs``: (key, label, unit).
MESH_FIGURES = (
    ("vertices", "vertices", ""),
    ("faces", "triangles", ""),
    ("volume_mm3", "volume", "mm^3"),
    ("area_mm2", "area", "mm^2"),
    ("watertight", "watertight", ""),
)


def key_figures(manifest: dict[str, Any]) -> list[KeyFigure]:
    """The manifest's key figures that this build has, each with its pointer."""
    rows = [_figure(manifest, pointer, label, unit) for pointer, label, unit in SCALAR_FIGURES]
    for i, entry in enumerate(resolve_or(manifest, "/metrics/blend/per_q", [])):
        for key, label, unit in PER_Q_FIGURES:
            label_q = f"q = {format_value(entry.get('q'))}: {label}"
            rows.append(_figure(manifest, f"/metrics/blend/per_q/{i}/{key}", label_q, unit))
    for i, entry in enumerate(manifest.get("outputs", [])):
        if "volume_mm3" in entry:
            for key, label, unit in MESH_FIGURES:
                rows.append(_figure(manifest, f"/outputs/{i}/{key}", f"{entry['path']}: {label}", unit))
    return [row for row in rows if row is not None]


def resolve_or(document: Any, pointer: str, default: Any) -> Any:
    """:func:`resolve_pointer`, or ``default`` when the pointer is absent."""
    try:
        return resolve_pointer(document, pointer)
    except KeyError:
        return default


def _figure(manifest: dict[str, Any], pointer: str, label: str, unit: str) -> KeyFigure | None:
    try:
        return KeyFigure(label, unit, pointer, resolve_pointer(manifest, pointer))
    except KeyError:
        return None


def input_rows(manifest: dict[str, Any]) -> list[tuple[str, str, str]]:
    """(path as the case names it, sha256, size in bytes) of every input file."""
    return [
        (str(i.get("path")), str(i.get("sha256")), format_value(i.get("bytes"))) for i in manifest.get("inputs", [])
    ]


def software_rows(manifest: dict[str, Any]) -> list[tuple[str, str, str]]:
    """(package, version the build recorded in the manifest, version that drew this report).

    The manifest's packages first, in its order, then those only the report
    uses; a version one side did not record reads "-".
    """
    recorded = {name: str(version) for name, version in manifest.get("software", {}).items()}
    drawing = software_versions(REPORT_PACKAGES)
    names = list(recorded) + [name for name in drawing if name not in recorded]
    return [(name, recorded.get(name, "-"), drawing.get(name, "-")) for name in names]


def mesh_checks(export_summary: dict[str, Any] | None) -> list[Check]:
    """The solid checks of every exported mesh, from ``export/summary.json``."""
    checks = []
    for name, f in (export_summary or {}).get("meshes", {}).items():
        euler = EULER_BY_KIND.get(f.get("kind"))
        rel = f.get("volume_rel_error")
        checks += [
            Check(name, "watertight", format_value(f["watertight"]), "yes", f["watertight"] is True),
            Check(name, "consistent winding", format_value(f["winding_consistent"]), "yes",
                  f["winding_consistent"] is True),
            Check(name, "one body", format_value(f["bodies"]), "1", f["bodies"] == 1),
            Check(name, "positive volume", f"{f['volume_mm3']:.6g} mm^3", "> 0", f["volume_mm3"] > 0),
            Check(name, "no self-folding (max rho * kappa)", format_value(f["max_rho_kappa"]), f"< {FOLD_LIMIT:g}",
                  f["max_rho_kappa"] < FOLD_LIMIT),
        ]
        if rel is not None:
            checks.append(Check(name, "volume vs integrated volume", f"{100 * rel:+.4f} %",
                                f"within +/- {100 * VOLUME_RTOL:g} %", abs(rel) <= VOLUME_RTOL))
        if euler is not None:
            checks.append(Check(name, f"Euler characteristic ({f['kind']})", format_value(f["euler"]), str(euler),
                                f["euler"] == euler))
    return checks


def fit_checks(fit_summary: dict[str, Any] | None) -> list[Check]:
    """The fit's own limits: no fold at q = 1 and a positive radius everywhere."""
    if not fit_summary:
        return []
    return [
        Check("fit", "no self-folding at q = 1 (max rho * kappa)", format_value(fit_summary["max_rho_kappa"]),
              f"< {FOLD_LIMIT:g}", fit_summary["max_rho_kappa"] < FOLD_LIMIT),
        Check("fit", "smallest radius", f"{fit_summary['min_rho_mm']:.6g} mm", "> 0", fit_summary["min_rho_mm"] > 0),
    ]


def output_checks(build_dir: Path, manifest: dict[str, Any]) -> list[Check]:
    """Every output the manifest lists is present with the recorded sha256."""
    checks = []
    for entry in manifest.get("outputs", []):
        file = Path(build_dir) / entry["path"]
        found = sha256_file(file) if file.is_file() else None
        text = "missing" if found is None else ("matches" if found == entry["sha256"] else f"differs ({found[:12]}...)")
        checks.append(Check(entry["path"], "file as recorded (sha256)", text, entry["sha256"][:12] + "...",
                            found == entry["sha256"]))
    return checks
