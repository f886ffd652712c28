"""One whole check of a build folder against a reference: meshes, kinematics, then the manifests' stage figures.

Both folders must be build folders (a ``manifest.json``); the fit metrics are
compared here because they live in that manifest (``metrics.fit.*_mm``), and
so are the case name and the inputs' sha256 that tell whether the two are
builds of the same case (:func:`case_warnings`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from softdesign.errors import ConfigError, InputDataError
from softdesign.pipeline.layout import MANIFEST
from softdesign.regression.feasibility import compare_feasibility
from softdesign.regression.figures import (
    RESIDUAL_FLOOR_MM,
    CheckOptions,
    CheckReport,
    Figure,
    missing_figure,
    read_json,
    residual_tolerance,
    scalar_figure,
)
from softdesign.regression.kinematics import compare_kinematics_files
from softdesign.regression.meshes import compare_mesh_folders, read_golden
from softdesign.regression.sections import compare_sections

#: Fit metrics compared first, in this order; other ``*_mm`` keys of metrics.fit follow, sorted.
FIT_KEYS = ("rms_mm", "p95_mm", "p99_mm", "max_mm", "holdout_rms_mm")

#: Fit metrics agree within check's relative tolerance of the reference plus this, mm (they are residuals).
FIT_FLOOR_MM = RESIDUAL_FLOOR_MM

#: A comparison of the two manifests: (build's, reference's, tolerances, notes to add to) -> figures.
ManifestComparison = Callable[[dict, dict, CheckOptions, list[str]], list[Figure]]


def check_build(
    build_dir: Path,
    reference_dir: Path,
    options: CheckOptions = CheckOptions(),
    progress: Callable[[str], None] | None = None,
) -> CheckReport:
    """Compare a build folder with a reference build folder.

    Parameters
    ----------
    build_dir, reference_dir : folders holding manifest.json, meshes/ and kinematics.json
    options : tolerances and sampling
    progress : called with a short note per mesh (e.g. to print on stderr)

    Raises
    ------
    ConfigError
        A folder is missing or is not a build folder (no manifest.json).
    InputDataError
        A JSON file is unreadable or malformed.
    """
    build_dir, reference_dir = Path(build_dir), Path(reference_dir)
    build_manifest = _read_manifest(build_dir, "BUILD_DIR")
    ref_manifest = _read_manifest(reference_dir, "--reference")
    golden = read_golden(reference_dir)
    notes: list[str] = []
    figures = compare_mesh_folders(build_dir, reference_dir, options, golden, progress)
    if not figures:
        notes.append("no mesh files under meshes/ on either side")
    figures += compare_kinematics_files(build_dir, reference_dir, options, notes)
    for _, compare in MANIFEST_COMPARISONS:
        figures += compare(build_manifest, ref_manifest, options, notes)
    warnings = tuple(case_warnings(build_manifest, ref_manifest))
    return CheckReport(build_dir, reference_dir, options, tuple(figures), tuple(notes), warnings)


#: What check compares in the manifests, in order, after the meshes and kinematics.json: the fit and the
#: feasibility by their own code, then every section of :data:`softdesign.regression.sections.SECTIONS` (links,
#: blend, the kinematics' arc check, design, mould, volume mesh).  A new stage's figures are a row of that table,
#: or a line here.
MANIFEST_COMPARISONS: tuple[tuple[str, ManifestComparison], ...] = (
    ("fit", lambda build, ref, options, notes: compare_fit(build, ref, options.distance_mm, notes, options.rtol)),
    ("feasibility", lambda build, ref, options, notes: compare_feasibility(build, ref, options.distance_mm, notes)),
    ("sections", compare_sections),
)


def case_warnings(build_manifest: dict, ref_manifest: dict) -> list[str]:
    """Why the two builds look like different cases: the case names, else the input files' contents.

    A check of one case against another measures the difference between two
    vessels, not a regression; it still runs (a user may mean it), with this
    warning.  Manifests without a case (or without inputs) are not judged.
    """
    ours, theirs = build_manifest.get("case"), ref_manifest.get("case")
    if not (isinstance(ours, dict) and isinstance(theirs, dict)):
        return []
    if ours.get("name") != theirs.get("name"):
        return [
            f"the build is case {ours.get('name')!r} and the reference case {theirs.get('name')!r}: every figure "
            "compares two different cases, not a change; give --reference a build of the same case"
        ]
    changed = _changed_inputs(build_manifest.get("inputs"), ref_manifest.get("inputs"))
    if changed:
        return [
            f"case {ours.get('name')!r} was built from other input files than the reference (sha256 differs: "
            f"{', '.join(changed)}): its figures move with the inputs, not only with a change of softdesign; "
            "rebuild the reference from the same files"
        ]
    return []


def _changed_inputs(ours: object, theirs: object) -> list[str]:
    """Input paths whose content (sha256) the other side does not have; the reference's are marked so."""
    if not (isinstance(ours, list) and isinstance(theirs, list)):
        return []
    ours, theirs = ([e for e in side if isinstance(e, dict)] for side in (ours, theirs))
    ours_hashes, theirs_hashes = ({e.get("sha256") for e in side} for side in (ours, theirs))
    changed = [str(e.get("path")) for e in ours if e.get("sha256") not in theirs_hashes]
    return changed + [f"{e.get('path')} (reference)" for e in theirs if e.get("sha256") not in ours_hashes]


def compare_fit(
    build_manifest: dict, ref_manifest: dict, tolerance_mm: float, notes: list[str], rtol: float | None = None
) -> list[Figure]:
    """Figures of ``metrics.fit.*_mm``: build minus reference, within ``tolerance_mm``.

    With ``rtol``, within the smaller of ``tolerance_mm`` and ``rtol`` of the reference plus FIT_FLOOR_MM: fit
    errors are often far below the distance tolerance (1e-4 mm on a synthetic vessel), where a change of a
    percent of them would pass an absolute tolerance unseen.
    """
    ours = _fit_metrics(build_manifest, "build " + MANIFEST)
    theirs = _fit_metrics(ref_manifest, "reference " + MANIFEST)
    if ours is None and theirs is None:
        notes.append("no metrics.fit on either side (no fit stage, or a case without a surface): not compared")
        return []
    if ours is None or theirs is None:
        return [missing_figure("fit", "metrics.fit", in_build=ours is not None)]
    keys = [k for k in FIT_KEYS if k in ours or k in theirs]
    keys += sorted(k for k in set(ours) | set(theirs) if k.endswith("_mm") and k not in FIT_KEYS)
    return [
        scalar_figure("fit", key, ours.get(key), theirs.get(key),
                      residual_tolerance(theirs.get(key), tolerance_mm, rtol, FIT_FLOOR_MM))
        for key in keys
    ]


def _fit_metrics(manifest: dict, where: str) -> dict | None:
    metrics = manifest.get("metrics") or {}
    if not isinstance(metrics, dict):
        raise InputDataError(f"{where}: 'metrics' must be an object, got {type(metrics).__name__}")
    fit = metrics.get("fit")
    if fit is not None and not isinstance(fit, dict):
        raise InputDataError(f"{where}: metrics.fit must be an object, got {type(fit).__name__}")
    return fit


def _read_manifest(folder: Path, what: str) -> dict:
    if not folder.is_dir():
        raise ConfigError(f"{what} {folder}: folder not found; give a build folder (softdesign build --out DIR)")
    path = folder / MANIFEST
    if not path.is_file():
        raise ConfigError(f"{what} {folder}: not a build folder (no {MANIFEST}); give the folder a build wrote")
    return read_json(path)
