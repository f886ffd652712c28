"""Write the generated vessels as VMTK would: a centerline .vtp and a capped wall per vessel.

The sample vessel's wall is written as STL (``data/demo``); the cohort's as
binary PLY (shared vertices: about a third of the bytes of the same mesh in
STL), so the committed cohort stays small.
"""

from __future__ import annotations

from pathlib import Path

from softdesign.io.formats import write_mesh
from softdesign.io.polylines_vtp import write_polylines_vtp
from softdesign.samples.cohort_vessels import COHORT_VARIANTS, VesselVariant, make_variant_vessel
from softdesign.samples.sample_vessel import SampleVessel, make_sample_vessel
from softdesign.samples.surfaces import sample_surface
from softdesign.samples.tree_vessel import TreeShape, make_tree_vessel, tree_surface
from softdesign.types import UNIT_SCALE_TO_MM

CENTERLINE = "centerline.vtp"
SURFACE = "surface.ply"
SAMPLE_SURFACE = "surface.stl"
TREE_SURFACE = "surface.ply"
#: Units of the files written per cohort case (default mm): one case is in cm, as some exports are.
COHORT_FILE_UNITS = {"coil": "cm"}


def write_vessel(out_dir: str | Path, vessel: SampleVessel, surface_name: str, units: str = "mm") -> list[Path]:
    """Write ``centerline.vtp`` and the capped wall ``surface_name`` of ``vessel`` into ``out_dir``.

    The centerline file holds two polylines (main vessel, side branch), both
    starting at the inlet and sharing the trunk's points, with the point
    array ``MaximumInscribedSphereRadius``, like ``vmtkcenterlines`` output.

    Parameters
    ----------
    out_dir : folder to write into (made if missing)
    vessel : the vessel, mm
    surface_name : file name of the wall; its suffix picks the format
    units : unit of the coordinates written: mm, cm or m

    Returns
    -------
    The two paths written.
    """
    if units not in UNIT_SCALE_TO_MM:
        raise ValueError(f"units must be one of {', '.join(UNIT_SCALE_TO_MM)}, got {units!r}")
    scale = 1.0 / UNIT_SCALE_TO_MM[units]
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    radius = [vessel.inscribed_radius("main") * scale, vessel.inscribed_radius("branch") * scale]
    polylines = [vessel.main * scale, vessel.branch * scale]  # x * 1.0 is x exactly: mm files keep their bytes
    centerline = write_polylines_vtp(out_dir / CENTERLINE, polylines, {"MaximumInscribedSphereRadius": radius})
    vertices, faces = sample_surface(vessel)
    surface = write_mesh(out_dir / surface_name, vertices * scale, faces)
    return [centerline, surface]


def write_sample(out_dir: str | Path) -> list[Path]:
    """Write ``centerline.vtp`` and ``surface.stl`` of the sample vessel into ``out_dir``."""
    return write_vessel(out_dir, make_sample_vessel(), SAMPLE_SURFACE)


def write_variant(out_dir: str | Path, variant: VesselVariant, units: str = "mm") -> list[Path]:
    """Write ``centerline.vtp`` and ``surface.ply`` of one cohort vessel, in ``units``."""
    return write_vessel(out_dir, make_variant_vessel(variant), SURFACE, units)


def write_cohort(out_root: str | Path) -> list[Path]:
    """Write every cohort vessel into ``out_root/<name>/``, in the units of COHORT_FILE_UNITS (default mm)."""
    written: list[Path] = []
    for variant in COHORT_VARIANTS:
        written += write_variant(Path(out_root) / variant.name, variant, COHORT_FILE_UNITS.get(variant.name, "mm"))
    return written


def write_tree(out_dir: str | Path, triangles: int, shape: TreeShape | None = None) -> list[Path]:
    """Write ``centerline.vtp`` (one polyline per leaf, root first) and ``surface.ply`` of the benchmark tree.

    The wall is binary PLY, as the cohort's: shared vertices, as SimVascular's .vtp models have them (an STL
    repeats each vertex six times and its reading merges them: a single-vessel cost of its own).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    tree = make_tree_vessel(shape or TreeShape())
    lines = [tree.path_points(k) for k in range(len(tree.paths))]
    centerline = write_polylines_vtp(out_dir / CENTERLINE, [p for p, _ in lines],
                                     {"MaximumInscribedSphereRadius": [r for _, r in lines]})
    surface = write_mesh(out_dir / TREE_SURFACE, *tree_surface(tree, triangles))
    return [centerline, surface]
