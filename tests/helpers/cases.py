"""Small synthetic cases written to a folder: case files and a straight vessel."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml


def write_case(folder: Path, name: str = "case", **sections) -> Path:
    """Write a case file from keyword sections; returns its path."""
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(sections, sort_keys=False))
    return path


def case_from(folder: Path, source: Path, extra: dict) -> Path:
    """A copy of the case file ``source`` in ``folder`` (its input paths made absolute) with ``extra`` over it."""
    case = yaml.safe_load(source.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((source.parent / case["final"][key]).resolve())
    case.update(extra)
    out = folder / f"{case['name']}.yaml"
    out.write_text(yaml.safe_dump(case, sort_keys=False))
    return out


def straight_tube(folder: Path, radius: float = 3.0, length: float = 40.0, scale: float = 1.0) -> tuple[Path, Path]:
    """A straight vessel along z: centerline .vtp (with radius) and capped surface .stl.

    ``scale`` multiplies every coordinate (1e-3 writes the same vessel in metres).
    """
    import trimesh

    from softdesign.io.polylines_vtp import write_polylines_vtp

    z = np.linspace(0.0, length, 81)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z]) * scale
    centerline = folder / "centerline.vtp"
    write_polylines_vtp(centerline, [points], {"MaximumInscribedSphereRadius": [np.full(len(z), radius * scale)]})
    tube = trimesh.creation.cylinder(radius=radius, height=length + 2.0, sections=48)
    tube.apply_translation([0.0, 0.0, length / 2])
    tube.apply_scale(scale)
    surface = folder / "surface.stl"
    tube.export(surface)
    return centerline, surface
