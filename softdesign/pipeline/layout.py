"""Every path inside a build folder, and every name beside it, named once.

Stages, the runner, the report, the regression check and the cohort summary
all find files through these names; nothing else spells a build-folder path.
Paths are POSIX, relative to the build folder.
"""

from __future__ import annotations

from softdesign.io.format_names import q_label

MANIFEST = "manifest.json"
#: How the last run went (each stage's status: ran, skipped, kept or stale, and its seconds): a log, outside the
#: manifest, so that the manifest and every output are the same bytes for the same inputs however they were reached.
RUN_LOG = "run.log.json"
KINEMATICS = "kinematics.json"
REPORT_DIR = "report"
MESHES_DIR = "meshes"
#: The record of one stage's run (its cache key and outputs with sha256) inside the stage's folder.
STAGE_RECORD = "stage.json"

INGEST_PATH = "ingest/path.npz"
INGEST_NETWORK = "ingest/network.npz"
INGEST_SURFACE = "ingest/surface.npz"
INGEST_INITIAL_PATH = "ingest/initial_path.npz"
INGEST_INITIAL_SURFACE = "ingest/initial_surface.npz"
INGEST_SUMMARY = "ingest/summary.json"
#: The centerline extracted from the surface (``final.centerline: auto``), VMTK's layout, in the case's units.
INGEST_CENTERLINE = "ingest/centerline.vtp"
#: The composed-chain design (issue 30): its document (``softdesign design --json`` prints the same) and the
#: deviation along the target and the chain's points, for the report.
DESIGN_SUMMARY = "design/summary.json"
DESIGN_PROFILE = "design/profile.npz"
BLEND_CURVES = "blend/curves.npz"
BLEND_SUMMARY = "blend/summary.json"
LINKS = "links/links.json"
FIT_SURFACE = "fit/surface.npz"
FIT_POINTS = "fit/points.npz"
FIT_SUMMARY = "fit/summary.json"
EXPORT_SUMMARY = "export/summary.json"
#: ParaView time series (q as the time) of the centerlines and, when .vtp is exported, of the meshes.
CENTERLINES_PVD = "centerlines.pvd"
MESHES_PVD = "meshes.pvd"
#: One glTF binary with a morph target per export q and an animation over q (when .glb is exported).
MORPH_GLB = "morph.glb"
MOULD_SUMMARY = "mould/summary.json"
#: How to make the body (material, mould, cores, supply, winding, casting, demoulding), and the figures it says.
FABRICATION = "fabrication.md"
FABRICATION_FIGURES = "fabrication/figures.json"
VOLUME_SUMMARY = "volume_mesh/summary.json"


# Beside the build folder ``<name>``, in the same parent (so a rename never crosses file systems), named
# ``.<name>.<role>``: a run's new folder (``staging-<pid>-<hex>``), an old folder set aside while the new one
# takes its name (``trash-<pid>-<hex>``, only where the two cannot be exchanged in one step) and the lock.


#: The file inside a run's staging folder, from its creation until it is swapped in: the folder is softdesign's.
STAGING_MARKER = ".softdesign-staging"


def staging_name(build_name: str, pid: int, token: str) -> str:
    """``.<name>.staging-<pid>-<token>`` (token: lowercase hex): a run's next folder, before it becomes ``<name>``."""
    return f".{build_name}.staging-{pid}-{token}"


def trash_name(build_name: str, pid: int, token: str) -> str:
    """``.<name>.trash-<pid>-<token>``: the previous folder while a two-rename swap is under way."""
    return f".{build_name}.trash-{pid}-{token}"


def sibling_role(build_name: str, entry_name: str) -> str | None:
    """``"staging"`` or ``"trash"`` when ``entry_name`` is one of those folders of build ``build_name``, else None.

    Exact names, not glob patterns: a build folder named ``*`` or ``a.staging-1`` claims only its own.
    """
    for role in ("staging", "trash"):
        rest = entry_name.removeprefix(f".{build_name}.{role}-")
        pid, _, token = rest.partition("-")
        if rest != entry_name and pid.isdigit() and token and set(token) <= set("0123456789abcdef"):
            return role
    return None


def lock_name(build_name: str) -> str:
    """``.<name>.lock``: the file a run locks while it writes build folder ``<name>``."""
    return f".{build_name}.lock"


def stage_record(stage: str) -> str:
    """``<stage>/stage.json``."""
    return f"{stage}/{STAGE_RECORD}"


def ingest_keyframe(index: int | str) -> str:
    """``ingest/keyframe_<index>.npz``: the intermediate keyframe centerline ``index``."""
    return f"ingest/keyframe_{index}.npz"


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


def mould_path(part: str, fmt: str) -> str:
    """``meshes/mould/half_a.stl``: a part of the casting mould of the body at q = 0."""
    return f"{MESHES_DIR}/mould/{part}.{fmt}"


def volume_mesh_path(q: float, suffix: str) -> str:
    """``meshes/volume/q_0.000.vtu`` (or ``.msh``): the tetrahedral mesh of the body at q."""
    return f"{MESHES_DIR}/volume/{q_label(q)}.{suffix}"


def chamber_surface_path(q: float) -> str:
    """``meshes/volume/chamber_q_0.000.stl``: the closed chamber surface of a hollow body at q, normals outwards."""
    return cavity_surface_path(q, "chamber")


def cavity_surface_path(q: float, cavity: str) -> str:
    """``meshes/volume/s1_c1_q_0.000.stl``: one cavity's closed surface (a chamber with its feed) at q."""
    return f"{MESHES_DIR}/volume/{cavity}_{q_label(q)}.stl"
