"""Write the project's sample vessel as VMTK would: centerline .vtp and capped surface .stl."""

from __future__ import annotations

from pathlib import Path

from softdesign.geometry.sample_vessel import make_sample_vessel
from softdesign.io.mesh_files import write_mesh
from softdesign.io.polylines_vtp import write_polylines_vtp
from softdesign.meshing.sample_surface import sample_surface


def write_sample(out_dir: str | Path) -> list[Path]:
    """Write ``centerline.vtp`` and ``surface.stl`` of the sample vessel into ``out_dir``.

    The centerline file holds two polylines (main vessel, side branch), both
    starting at the inlet and sharing the trunk's points, with the point
    array ``MaximumInscribedSphereRadius``, like ``vmtkcenterlines`` output.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    vessel = make_sample_vessel()
    centerline = write_polylines_vtp(
        out_dir / "centerline.vtp",
        [vessel.main, vessel.branch],
        {"MaximumInscribedSphereRadius": [vessel.inscribed_radius("main"), vessel.inscribed_radius("branch")]},
    )
    vertices, faces = sample_surface(vessel)
    surface = write_mesh(out_dir / "surface.stl", vertices, faces)
    return [centerline, surface]
