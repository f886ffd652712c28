"""The volume meshes in the report: a table of their quality figures and their checks (issue 16).

A new module for the report to call (``volume_mesh/summary.json`` in, a
:class:`~softdesign.report.html_page.Table` and
:class:`~softdesign.report.tables.Check` rows out; both empty when the build
has no volume mesh); the page's wiring is left to the report's writer.
"""

from __future__ import annotations

from typing import Any

from softdesign.report.html_page import Table, plain_table
from softdesign.report.tables import Check


def _rows(summary: dict[str, Any] | None) -> list[dict[str, Any]]:
    return list((summary or {}).get("per_q", [])) if (summary or {}).get("requested") else []


def volume_mesh_table(summary: dict[str, Any] | None) -> Table | None:
    """One row per meshed q: tetrahedra, volume error, extreme angles, radius-edge, size, 3D figures; None if none.

    No mesher time: the page is a function of the build (issue 35); the times are in the build's printed log."""
    rows = _rows(summary)
    if not rows:
        return None
    header = ("q", "tets", "volume vs body", "in chamber", "min dihedral", "max dihedral", "max radius-edge",
              "size / mean edge", "3D stretch max", "3D stress max")
    body = [(
        f"{f['q']:.3f}", str(f["tets"]), f"{100 * f['volume_rel_error']:+.3f} %",
        "-" if f.get("chamber_centroids_inside") is None else str(f["chamber_centroids_inside"]),
        f"{f['min_dihedral_deg']:.2f} deg", f"{f['max_dihedral_deg']:.2f} deg", f"{f['max_radius_edge']:.2f}",
        f"{f['size_mm']:g} / " + ("-" if f.get("mean_edge_mm") is None else f"{f['mean_edge_mm']:.2f} mm"),
        *_strain_cells(f.get("strain")),
    ) for f in rows]
    swept = bool((summary or {}).get("deterministic"))
    return plain_table(f"Volume meshes ({'swept' if swept else 'fTetWild'}): meshes/volume/q_*.vtu and .msh", header,
                       body, ("num",) * len(header))


def _strain_cells(strain: dict[str, Any] | None) -> tuple[str, str]:
    """The swept mesh's largest 3D stretch and principal stress at this q (fTetWild's meshes have none)."""
    if strain is None:
        return "-", "-"
    stress = strain["stress_max_kpa"]
    return f"{strain['stretch_max']['value']:.4f}", "-" if stress is None else f"{stress['value']:.1f} kPa"


def volume_mesh_checks(summary: dict[str, Any] | None) -> list[Check]:
    """Every tetrahedron positive, the volume within its tolerance, the chamber empty, per meshed q."""
    checks = []
    for f in _rows(summary):
        name = f"volume mesh q={f['q']:.3f}"
        rtol = f["volume_rtol"]
        checks += [
            Check(name, "every tetrahedron positive", f"min {f['min_tet_volume_mm3']:.3g} mm^3", "> 0",
                  f["min_tet_volume_mm3"] > 0),
            Check(name, "volume vs body", f"{100 * f['volume_rel_error']:+.3f} %", f"within +/- {100 * rtol:g} %",
                  abs(f["volume_rel_error"]) <= rtol),
        ]
        if f.get("chamber_centroids_inside") is not None:  # fTetWild's meshes (the swept mesh has no chamber to fill)
            checks.append(Check(name, "tetrahedra in the chamber", str(f["chamber_centroids_inside"]), "0",
                                f["chamber_centroids_inside"] == 0))
    return checks
