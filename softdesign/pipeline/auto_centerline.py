"""``final.centerline: auto``: the centerline extracted from ``final.surface`` at ingest, and its kept file.

The extraction is :func:`softdesign.centerline.extract.extract_centerlines`, the same as ``softdesign
centerline`` runs; the surface is an input of the build (hashed, in the manifest), so the extracted
centerline is redone exactly when the surface or the case's ``final`` keys change.  Its file,
``ingest/centerline.vtp`` (VMTK's layout, in the case's ``units``, so ``final.centerline`` can name it
in a later case), is an output of the ingest stage like any other.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.centerline.extract import CenterlineOptions, Centerlines, extract_centerlines
from softdesign.geometry.network import CenterlineNetwork, Polyline
from softdesign.geometry.plausibility import check_vessel_scale
from softdesign.pipeline import layout
from softdesign.pipeline.store import Staging
from softdesign.types import UNIT_SCALE_TO_MM

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case


def extract_for_case(case: Case) -> tuple[CenterlineNetwork, Centerlines]:
    """The network extracted from ``case.final.surface`` (mm), one polyline per outlet, and the extraction.

    ``final.inlet`` (in ``units``) names the inlet opening; every other opening is an outlet.
    """
    from softdesign.io.centerline_vtp import read_face_regions
    from softdesign.io.surface import read_surface

    surface = case.final.surface
    if surface is None:  # the case file's validation requires it
        raise ValueError("final.centerline: auto without final.surface")
    scale = UNIT_SCALE_TO_MM[case.units]
    surface_scale = UNIT_SCALE_TO_MM[case.final.surface_units] if case.final.surface_units else scale
    inlet = None if case.final.inlet is None else np.asarray(case.final.inlet, float) * scale
    options = CenterlineOptions(inlet=inlet, regions=read_face_regions(surface))
    vertices, faces = read_surface(surface, surface_scale)
    # a wrong unit is refused before the extraction's work, from the surface's largest extent
    check_vessel_scale(float(np.ptp(vertices, axis=0).max()), None, case.final.surface_units or case.units,
                       f"final.surface {surface.name} (its largest extent)")
    extracted = extract_centerlines(vertices, faces, options, f"final.surface {surface.name}")
    polylines = tuple(Polyline(p, r) for p, r in zip(extracted.paths, extracted.radii, strict=True))
    return CenterlineNetwork(polylines, source=f"auto ({surface.name})"), extracted


def write_extracted(extracted: Centerlines, staging: Staging, units: str) -> None:
    """Keep the extracted centerline as ``ingest/centerline.vtp``, in ``units`` (the case's)."""
    from softdesign.io.centerline_vtp import write_centerlines_vtp

    write_centerlines_vtp(staging.staged_path(layout.INGEST_CENTERLINE), extracted, 1.0 / UNIT_SCALE_TO_MM[units])
    staging.record(layout.INGEST_CENTERLINE)


def extraction_summary(extracted: Centerlines) -> dict[str, Any]:
    """What the manifest says about the extraction (mm)."""
    return {
        "file": layout.INGEST_CENTERLINE,
        "endpoints": extracted.endpoints,
        "inlet_mm": [float(v) for v in extracted.inlet],
        "outlets_mm": [[float(v) for v in o] for o in extracted.outlets],
        "voronoi_vertices": extracted.voronoi_vertices,
        "continued_mm": [[round(v, 6) for v in ends] for ends in extracted.continued_mm],
        "short_of_opening_mm": [[round(v, 6) for v in ends] for ends in extracted.short_mm],
    }


def continuation_note(extracted: Centerlines, units: str = "mm") -> str:
    """How far each extracted path's ends were continued straight past the Voronoi diagram, for the ingest notes
    (lengths in the case's ``units``, with mm beside them otherwise)."""
    from softdesign.pipeline.length_text import length_text

    ends = "; ".join(f"path {k}: {length_text(a, units)} at the inlet, {length_text(b, units)} at the outlet"
                     for k, (a, b) in enumerate(extracted.continued_mm))
    short = [f"path {k} stops {length_text(max(gap), units)} short of an opening's centre (the straight run would "
             "leave the surface)" for k, gap in enumerate(extracted.short_mm) if max(gap) > 0.0]
    return (f"extracted centerline: the ends continued straight past the Voronoi diagram to the openings' centres "
            f"(a rounded end: to the centre of the sphere touching its tip): {ends}" + "".join(f"; {s}" for s in short))
