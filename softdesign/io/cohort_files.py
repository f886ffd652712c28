"""Write the sample cohort's vessels as VMTK would: a centerline .vtp and a capped wall per case.

The wall is written as binary PLY (shared vertices: about a third of the
bytes of the same mesh in STL), so the committed cohort stays small.
"""

from __future__ import annotations

from pathlib import Path

from softdesign.geometry.cohort_vessels import COHORT_VARIANTS, VesselVariant, make_variant_vessel
from softdesign.io.mesh_files import write_mesh
from softdesign.io.polylines_vtp import write_polylines_vtp
from softdesign.meshing.sample_surface import sample_surface
from softdesign.types import UNIT_SCALE_TO_MM

CENTERLINE = "centerline.vtp"
SURFACE = "surface.ply"
#: Units of the files written per case (default mm): one case is in cm, as some exports are.
COHORT_FILE_UNITS = {"coil": "cm"}


def write_variant(out_dir: str | Path, variant: VesselVariant, units: str = "mm") -> list[Path]:
    """Write ``centerline.vtp`` (main path and branch, MaximumInscribedSphereRadius) and ``surface.ply``.

    Parameters
    ----------
    out_dir : folder to write into (made if missing)
    variant : the vessel
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
    vessel = make_variant_vessel(variant)
    centerline = write_polylines_vtp(
        out_dir / CENTERLINE,
        [vessel.main * scale, vessel.branch * scale],
        {"MaximumInscribedSphereRadius": [vessel.inscribed_radius("main") * scale, vessel.inscribed_radius("branch") * scale]},
    )
    vertices, faces = sample_surface(vessel)
    surface = write_mesh(out_dir / SURFACE, vertices * scale, faces)
    return [centerline, surface]


def write_cohort(out_root: str | Path) -> list[Path]:
    """Write every cohort vessel into ``out_root/<name>/``, in the units of COHORT_FILE_UNITS (default mm)."""
    written: list[Path] = []
    for variant in COHORT_VARIANTS:
        written += write_variant(Path(out_root) / variant.name, variant, COHORT_FILE_UNITS.get(variant.name, "mm"))
    return written
