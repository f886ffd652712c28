"""Compare a build folder with a reference build folder, figure by figure (``softdesign check``).

What is compared, and against which tolerance (:class:`CheckOptions`):

- every mesh file under ``meshes/`` (.stl .ply .obj .glb) present on either
  side, by name, through :func:`softdesign.meshing.compare.compare_meshes`:
  symmetric surface distance max and RMS (``distance_mm``), relative change of
  volume and area (``rtol``), watertightness (must equal the reference's).
  A mesh on one side only, or one that cannot be read, fails;
- ``kinematics.json`` per q and link: translation difference of the link
  transform (mm, ``distance_mm``), angle of the rotation between the two
  transforms (rad, ``rotation_rad``), link length and POE theta1 (mm,
  ``distance_mm``), POE theta2 (rad, ``rotation_rad``); the same for each
  pose's ``base_to_tip`` and ``base_to_world`` (where present); the frame
  convention must match.  A pose is matched by its q, one value or one per
  link as the kinematics stage writes it;
- the fit metrics ``manifest.json: metrics.fit.*_mm`` (``distance_mm``).

Any change beyond tolerance fails, an improvement included: a reference is
updated on purpose, never drifted past.

The rotation tolerance is a fixed angle rather than ``distance_mm / link
length``: a rotation error in one link swings every link after it, so a short
link does not earn a looser angle; 1e-4 rad moves the tip of a 100 mm
actuator by 0.01 mm, the default ``distance_mm``.

A reference may hold decimated meshes.  The step that makes it then writes
``REF_DIR/golden.json``::

    {"meshes": {"meshes/q_0.000.stl": {"distance_max_mm": 0.004,
                                       "volume_rel_change": -1e-4,
                                       "area_rel_change": -3e-4}}, ...}

with the figures of the stored mesh against the full-resolution one
(:func:`decimation_entry`), and check adds them to that mesh's tolerances:
``distance_mm + distance_max_mm`` for max and RMS distance (a point within
``distance_mm`` of the full surface is within ``distance_mm + distance_max_mm``
of the stored one: the triangle inequality), ``rtol + |volume_rel_change|`` and
``rtol + |area_rel_change|`` (to first order).  Other keys (versions, case
hash) are ignored here.  Watertightness is compared with the stored mesh, so
the golden step must decimate without opening it.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from softdesign.errors import ConfigError, InputDataError, SoftdesignError
from softdesign.meshing.compare import DEFAULT_SAMPLES, MeshDifference, compare_meshes

MESH_SUFFIXES = (".stl", ".ply", ".obj", ".glb")
MANIFEST = "manifest.json"
KINEMATICS = "kinematics.json"
GOLDEN = "golden.json"
#: Fit metrics compared first, in this order; other ``*_mm`` keys of metrics.fit follow, sorted.
FIT_KEYS = ("rms_mm", "p95_mm", "p99_mm", "max_mm", "holdout_rms_mm")
#: Decimals of q that identify a pose (q values are written as the case file gives them).
Q_DECIMALS = 9
#: Chain-level transforms of a pose, compared like link transforms when either side has them.
POSE_TRANSFORMS = ("base_to_tip", "base_to_world")

Value = Optional[float | bool | str]


@dataclass(frozen=True)
class CheckOptions:
    """Tolerances of a check, and the sampling of the surface distance.

    Attributes
    ----------
    distance_mm : surface distance, transform translation, lengths, fit metrics, mm
    rtol : relative change of volume and area
    rotation_rad : rotation between link transforms and POE theta2, rad
    samples : fewest surface points sampled per mesh
    """

    distance_mm: float = 0.01
    rtol: float = 1e-3
    rotation_rad: float = 1e-4
    samples: int = DEFAULT_SAMPLES

    def __post_init__(self) -> None:
        for name, option in (("distance_mm", "--tolerance-mm"), ("rtol", "--rtol"), ("rotation_rad", "--rotation-tol")):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ConfigError(f"{option}: expected a finite tolerance >= 0, got {value}")
        if self.samples < 1:
            raise ConfigError(f"samples: expected >= 1, got {self.samples}")


@dataclass(frozen=True)
class Figure:
    """One compared figure: how much it moved, its tolerance and the verdict.

    ``change`` is build minus reference for scalars, the distance or angle for
    poses and meshes, None where a thing is missing; ``passed`` is
    ``|change| <= tolerance`` (or equality where ``tolerance`` is None).
    """

    item: str
    figure: str
    change: Value
    tolerance: Optional[float]
    passed: bool
    build: Value = None
    reference: Value = None
    note: str = ""

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: field name -> value, a non-finite number as None."""
        return {key: _json_value(value) for key, value in asdict(self).items()}


@dataclass(frozen=True)
class CheckReport:
    """Every figure of one check, in order: meshes, kinematics, fit."""

    build_dir: Path
    reference_dir: Path
    options: CheckOptions
    figures: tuple[Figure, ...]
    notes: tuple[str, ...] = field(default=())

    @property
    def passed(self) -> bool:
        """True when every figure is within its tolerance."""
        return all(f.passed for f in self.figures)

    @property
    def failures(self) -> tuple[Figure, ...]:
        """The figures outside tolerance."""
        return tuple(f for f in self.figures if not f.passed)

    def as_dict(self) -> dict[str, Any]:
        """The JSON object ``softdesign check --json`` prints."""
        return {
            "passed": self.passed,
            "build": self.build_dir.as_posix(),
            "reference": self.reference_dir.as_posix(),
            "tolerances": {key: getattr(self.options, key) for key in ("distance_mm", "rtol", "rotation_rad")},
            "failures": len(self.failures),
            "figures": [f.as_dict() for f in self.figures],
            "notes": list(self.notes),
        }


@dataclass(frozen=True)
class DecimationError:
    """What a golden reference lost by decimating one mesh (read from golden.json)."""

    distance_max_mm: float = 0.0
    volume_rel_change: float = 0.0
    area_rel_change: float = 0.0


def check_build(
    build_dir: Path,
    reference_dir: Path,
    options: CheckOptions = CheckOptions(),
    progress: Optional[Callable[[str], None]] = None,
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
    figures += _compare_kinematics_files(build_dir, reference_dir, options, notes)
    figures += compare_fit(build_manifest, ref_manifest, options.distance_mm, notes)
    return CheckReport(build_dir, reference_dir, options, tuple(figures), tuple(notes))


def decimation_entry(difference: MeshDifference) -> dict[str, float]:
    """The golden.json record of one stored mesh: ``compare_meshes(stored, full_resolution)`` figures."""
    return {
        "distance_max_mm": difference.distance_max_mm,
        "volume_rel_change": difference.volume_rel_change,
        "area_rel_change": difference.area_rel_change,
    }


def read_golden(reference_dir: Path) -> dict[str, DecimationError]:
    """Per-mesh decimation errors from ``reference_dir/golden.json``; empty when there is none."""
    path = Path(reference_dir) / GOLDEN
    if not path.is_file():
        return {}
    meshes = _read_json(path).get("meshes", {})
    if not isinstance(meshes, dict):
        raise InputDataError(f"{path}: 'meshes' must be an object of mesh path -> errors, got {type(meshes).__name__}")
    errors = {}
    for name, entry in meshes.items():
        values = {}
        for key in ("distance_max_mm", "volume_rel_change", "area_rel_change"):
            value = entry.get(key, 0.0) if isinstance(entry, dict) else None
            if not _is_number(value) or not math.isfinite(value):
                raise InputDataError(f"{path}: meshes.{name}.{key} must be a finite number, got {value!r}")
            values[key] = abs(float(value))
        errors[name] = DecimationError(**values)
    return errors


def mesh_names(build_dir: Path) -> set[str]:
    """Mesh files under ``build_dir/meshes``, as paths relative to ``build_dir`` (``meshes/q_0.000.stl``)."""
    root = Path(build_dir) / "meshes"
    if not root.is_dir():
        return set()
    found = (p for p in root.rglob("*") if p.is_file() and p.suffix.lower() in MESH_SUFFIXES)
    return {p.relative_to(build_dir).as_posix() for p in found}


def compare_mesh_folders(
    build_dir: Path,
    reference_dir: Path,
    options: CheckOptions,
    golden: dict[str, DecimationError],
    progress: Optional[Callable[[str], None]] = None,
) -> list[Figure]:
    """Figures of every mesh present on either side, sorted by name."""
    ours, theirs = mesh_names(build_dir), mesh_names(reference_dir)
    figures: list[Figure] = []
    for name in sorted(ours | theirs):
        if name not in ours or name not in theirs:
            figures.append(_missing(name, "mesh file", in_build=name in ours))
            continue
        if progress is not None:
            progress(f"check: comparing {name}")
        try:
            mesh, ref = _read_mesh(build_dir / name), _read_mesh(reference_dir / name)
            difference = compare_meshes(*mesh, *ref, samples=options.samples)
        except SoftdesignError as err:
            figures.append(Figure(name, "readable", None, None, False, note=str(err)))
            continue
        figures += mesh_figures(name, difference, options, golden.get(name, DecimationError()))
    return figures


def mesh_figures(name: str, diff: MeshDifference, options: CheckOptions, allowance: DecimationError) -> list[Figure]:
    """The five figures of one mesh pair (four for open surfaces: no volume); tolerances widened by the
    reference's decimation error."""
    distance_tol = options.distance_mm + allowance.distance_max_mm
    note = "tolerance + golden.json decimation error" if allowance != DecimationError() else ""
    figures = [
        Figure(name, key, value, distance_tol, value <= distance_tol, note=note)
        for key, value in (("distance_max_mm", diff.distance_max_mm), ("distance_rms_mm", diff.distance_rms_mm))
    ]
    closed = diff.watertight and diff.reference_watertight  # an open surface (a region file) encloses nothing
    for key, value, extra in (
        ("volume_rel_change", diff.volume_rel_change, allowance.volume_rel_change),
        ("area_rel_change", diff.area_rel_change, allowance.area_rel_change),
    ):
        if key == "volume_rel_change" and not closed:
            continue
        tolerance = options.rtol + extra
        figures.append(Figure(name, key, value, tolerance, abs(value) <= tolerance, note=note))
    same = diff.watertight == diff.reference_watertight
    figures.append(Figure(name, "watertight", None, None, same, diff.watertight, diff.reference_watertight))
    return figures


def compare_fit(build_manifest: dict, ref_manifest: dict, tolerance_mm: float, notes: list[str]) -> list[Figure]:
    """Figures of ``metrics.fit.*_mm``: build minus reference, within ``tolerance_mm``."""
    ours = _fit_metrics(build_manifest, "build " + MANIFEST)
    theirs = _fit_metrics(ref_manifest, "reference " + MANIFEST)
    if ours is None and theirs is None:
        notes.append("no metrics.fit on either side (no fit stage, or a case without a surface): not compared")
        return []
    if ours is None or theirs is None:
        return [_missing("fit", "metrics.fit", in_build=ours is not None)]
    keys = [k for k in FIT_KEYS if k in ours or k in theirs]
    keys += sorted(k for k in set(ours) | set(theirs) if k.endswith("_mm") and k not in FIT_KEYS)
    return [scalar_figure("fit", key, ours.get(key), theirs.get(key), tolerance_mm) for key in keys]


def scalar_figure(item: str, figure: str, value: Any, reference: Any, tolerance: float) -> Figure:
    """``value - reference`` within ``tolerance``; a value on one side only fails."""
    if value is None or reference is None:
        if value is None and reference is None:
            return Figure(item, figure, None, tolerance, True, note="absent on both sides")
        return _missing(item, figure, in_build=value is not None)
    if not (_is_number(value) and _is_number(reference)):
        return Figure(item, figure, None, tolerance, False, str(value), str(reference), "expected two numbers")
    change = float(value) - float(reference)
    return Figure(item, figure, change, tolerance, abs(change) <= tolerance, float(value), float(reference))


def pose_difference(pose: np.ndarray, ref_pose: np.ndarray) -> tuple[float, float]:
    """Translation difference (mm) and angle of ``R_ref^T R`` (rad, in [0, pi]) of two (4, 4) poses."""
    translation = float(np.linalg.norm(pose[:3, 3] - ref_pose[:3, 3]))
    relative = ref_pose[:3, :3].T @ pose[:3, :3]
    skew = relative - relative.T
    skew = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    # atan2 keeps the angle accurate near 0, where acos((trace - 1) / 2) loses half the digits.
    angle = float(np.arctan2(0.5 * np.linalg.norm(skew), 0.5 * (np.trace(relative) - 1.0)))
    return translation, angle


def compare_kinematics(build: dict, ref: dict, options: CheckOptions, where: str = KINEMATICS) -> list[Figure]:
    """Figures of two ``kinematics.json`` objects: frames, then per q each link and the chain transforms."""
    frames_ok = build.get("frames") == ref.get("frames")
    figures = [Figure("kinematics", "frames", None, None, frames_ok, build.get("frames"), ref.get("frames"))]
    ours, theirs = _keyed(build, "poses", "q", where), _keyed(ref, "poses", "q", "reference " + where)
    for q in sorted(set(ours) | set(theirs), key=_numeric_order):
        item = f"kinematics q={q}"
        if q not in ours or q not in theirs:
            figures.append(_missing(item, "pose", in_build=q in ours))
            continue
        figures += _pose_figures(item, ours[q], theirs[q], options, f"{where}: pose q={q}")
    return figures


def _pose_figures(item: str, pose: dict, ref_pose: dict, options: CheckOptions, where: str) -> list[Figure]:
    ours, theirs = _keyed(pose, "links", "index", where), _keyed(ref_pose, "links", "index", "reference " + where)
    figures: list[Figure] = []
    for index in sorted(set(ours) | set(theirs), key=_numeric_order):
        link_item = f"{item} link {index}"
        if index not in ours or index not in theirs:
            figures.append(_missing(link_item, "link", in_build=index in ours))
            continue
        figures += _link_figures(link_item, ours[index], theirs[index], options, f"{where} link {index}")
    for key in POSE_TRANSFORMS:
        if pose.get(key) is not None or ref_pose.get(key) is not None:
            figures += _transform_figures(f"{item} {key}", pose.get(key), ref_pose.get(key), options, f"{where} {key}")
    return figures


def _link_figures(item: str, link: dict, ref_link: dict, options: CheckOptions, where: str) -> list[Figure]:
    figures = _transform_figures(item, link.get("transform"), ref_link.get("transform"), options, where)
    poe, ref_poe = link.get("poe") or {}, ref_link.get("poe") or {}
    for figure, value, reference, tolerance in (
        ("length_mm", link.get("length"), ref_link.get("length"), options.distance_mm),
        ("poe_theta1_mm", poe.get("theta1"), ref_poe.get("theta1"), options.distance_mm),
        ("poe_theta2_rad", poe.get("theta2"), ref_poe.get("theta2"), options.rotation_rad),
    ):
        figures.append(scalar_figure(item, figure, value, reference, tolerance))
    return figures


def _transform_figures(
    item: str, transform: Any, ref_transform: Any, options: CheckOptions, where: str
) -> list[Figure]:
    if transform is None or ref_transform is None:
        return [_missing(item, "transform", in_build=transform is not None)]
    translation, angle = pose_difference(_pose(transform, where), _pose(ref_transform, "reference " + where))
    return [
        Figure(item, "translation_mm", translation, options.distance_mm, translation <= options.distance_mm),
        Figure(item, "rotation_rad", angle, options.rotation_rad, angle <= options.rotation_rad),
    ]


def _compare_kinematics_files(
    build_dir: Path, reference_dir: Path, options: CheckOptions, notes: list[str]
) -> list[Figure]:
    ours, theirs = build_dir / KINEMATICS, reference_dir / KINEMATICS
    if not ours.is_file() and not theirs.is_file():
        notes.append(f"no {KINEMATICS} on either side: kinematics not compared")
        return []
    if not ours.is_file() or not theirs.is_file():
        return [_missing("kinematics", KINEMATICS, in_build=ours.is_file())]
    return compare_kinematics(_read_json(ours), _read_json(theirs), options, ours.as_posix())


def _keyed(parent: dict, field_name: str, key: str, where: str) -> dict[str, dict]:
    """``parent[field_name]`` (a list of objects) keyed by the text of each one's ``key`` (a number or numbers)."""
    entries = parent.get(field_name)
    if not isinstance(entries, list):
        raise InputDataError(f"{where}: '{field_name}' must be a list, got {type(entries).__name__}")
    out: dict[str, dict] = {}
    for i, entry in enumerate(entries):
        value = entry.get(key) if isinstance(entry, dict) else None
        values = value if isinstance(value, list) and value else [value]
        if not all(_is_number(v) for v in values):
            raise InputDataError(f"{where}: {field_name}[{i}].{key} must be a number or numbers, got {value!r}")
        # One q per link, all equal, is the same pose as that single q: name it once.
        texts = [f"{round(v, Q_DECIMALS):.12g}" for v in values]
        out[texts[0] if len(set(texts)) == 1 else ",".join(texts)] = entry
    return out


def _numeric_order(key: str) -> list[float]:
    return [float(part) for part in key.split(",")]


def _pose(value: Any, where: str) -> np.ndarray:
    try:
        pose = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):  # ragged or non-numeric lists
        pose = np.zeros(0)
    if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
        raise InputDataError(f"{where}: expected a finite 4x4 transform, got {str(value)[:80]}")
    return pose


def _fit_metrics(manifest: dict, where: str) -> Optional[dict]:
    metrics = manifest.get("metrics") or {}
    if not isinstance(metrics, dict):
        raise InputDataError(f"{where}: 'metrics' must be an object, got {type(metrics).__name__}")
    fit = metrics.get("fit")
    if fit is not None and not isinstance(fit, dict):
        raise InputDataError(f"{where}: metrics.fit must be an object, got {type(fit).__name__}")
    return fit


def _missing(item: str, figure: str, in_build: bool) -> Figure:
    """A thing on one side only: always a failure."""
    sides = ("present", "missing") if in_build else ("missing", "present")
    return Figure(item, figure, None, None, False, *sides)


def _read_mesh(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and faces (F, 3) of a mesh file, shared vertices merged (STL stores none)."""
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh", process=True)
    except Exception as err:  # trimesh raises many types for malformed files
        raise InputDataError(f"{path}: cannot read the mesh ({type(err).__name__}: {err})") from err
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputDataError(f"{path}: the mesh has no triangles")
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


def _read_manifest(folder: Path, what: str) -> dict:
    if not folder.is_dir():
        raise ConfigError(f"{what} {folder}: folder not found; give a build folder (softdesign build --out DIR)")
    path = folder / MANIFEST
    if not path.is_file():
        raise ConfigError(f"{what} {folder}: not a build folder (no {MANIFEST}); give the folder a build wrote")
    return _read_json(path)


def _read_json(path: Path) -> dict:
    try:
        payload = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputDataError(f"{path}: cannot read JSON ({err}); rebuild it") from err
    if not isinstance(payload, dict):
        raise InputDataError(f"{path}: expected a JSON object, got {type(payload).__name__}")
    return payload


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _json_value(value: Value) -> Value:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
