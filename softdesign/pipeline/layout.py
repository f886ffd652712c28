"""Every path inside a build folder, named once.

Stages, the runner, the report, the regression check and the cohort summary
all find files through these names; nothing else spells a build-folder path.
Paths are POSIX, relative to the build folder.
"""

from __future__ import annotations

MANIFEST = "manifest.json"
KINEMATICS = "kinematics.json"
REPORT_DIR = "report"
MESHES_DIR = "meshes"
#: The record of one stage's run (its cache key and outputs with sha256) inside the stage's folder.
STAGE_RECORD = "stage.json"
#: Staging folders sit beside the build folder: ``.<build folder name>.staging-<pid>-XXXX``.
STAGING_PREFIX = ".staging-"

INGEST_PATH = "ingest/path.npz"
INGEST_NETWORK = "ingest/network.npz"
INGEST_SURFACE = "ingest/surface.npz"
INGEST_INITIAL_PATH = "ingest/initial_path.npz"
INGEST_INITIAL_SURFACE = "ingest/initial_surface.npz"
INGEST_SUMMARY = "ingest/summary.json"
BLEND_CURVES = "blend/curves.npz"
BLEND_SUMMARY = "blend/summary.json"
LINKS = "links/links.json"
FIT_SURFACE = "fit/surface.npz"
FIT_POINTS = "fit/points.npz"
FIT_SUMMARY = "fit/summary.json"
EXPORT_SUMMARY = "export/summary.json"


def stage_record(stage: str) -> str:
    """``<stage>/stage.json``."""
    return f"{stage}/{STAGE_RECORD}"


def ingest_keyframe(index: int | str) -> str:
    """``ingest/keyframe_<index>.npz``: the intermediate keyframe centerline ``index``."""
    return f"ingest/keyframe_{index}.npz"


def q_label(q: float) -> str:
    """``q_0.500``: three decimals, as DESIGN.md names the meshes."""
    return f"q_{q:.3f}"


def mesh_path(q: float, fmt: str) -> str:
    """``meshes/q_0.500.stl``."""
    return f"{MESHES_DIR}/{q_label(q)}.{fmt}"


def region_dir(q: float) -> str:
    """``meshes/q_0.500/``: one folder per q, so ``meshes/q_*.stl`` stays the solids."""
    return f"{MESHES_DIR}/{q_label(q)}/"


def region_path(q: float, region: str) -> str:
    """``meshes/q_0.500/wall.stl``."""
    return f"{region_dir(q)}{region}.stl"


def centerline_path(q: float) -> str:
    """``centerlines/q_0.500.vtp``: c(q, l) with its frames."""
    return f"centerlines/{q_label(q)}.vtp"
