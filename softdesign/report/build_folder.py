"""Reload a build folder for the report: the manifest and every stage's kept result.

The report reads only what ``softdesign build`` (or a stage command) kept:
``manifest.json``, ``ingest/``, ``blend/``, ``links/``, ``kinematics.json``
(these are required), ``fit/`` and ``export/`` with ``meshes/`` (optional: a folder
built only through ``softdesign kinematics`` gets a report without them).
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from softdesign.errors import InputDataError
from softdesign.pipeline import layout
from softdesign.pipeline.layout import MANIFEST
from softdesign.pipeline.stages.blend import BlendResult, load_blend
from softdesign.pipeline.stages.export import load_export, mesh_name
from softdesign.pipeline.stages.fit import FitResult, load_fit
from softdesign.pipeline.stages.ingest import IngestResult, load_ingest
from softdesign.pipeline.stages.kinematics import KinematicsResult, load_kinematics
from softdesign.pipeline.stages.links import load_links
from softdesign.report.build_check import check_manifest


@dataclass(frozen=True)
class BuildData:
    """Everything the report draws from one build folder.

    Attributes
    ----------
    build_dir : the build folder
    manifest : ``manifest.json`` as loaded
    ingest, blend, kinematics : the kept stage results (the link chain is rebuilt)
    fit : the kept fit (radius field, points, summary), or None when not built
    export_summary : ``export/summary.json``, or None when not built
    """

    build_dir: Path
    manifest: dict[str, Any]
    ingest: IngestResult
    blend: BlendResult
    kinematics: KinematicsResult
    fit: FitResult | None
    export_summary: dict[str, Any] | None

    @cached_property
    def vessel_display(self) -> tuple[Any, Any, float]:
        """(vertices, faces, display error mm): the input vessel as the report shows it, found once per build data.

        :func:`softdesign.report.display_mesh.decimated_vessel`; the 3D view and the surface figure both show it.
        """
        from softdesign.report.display_mesh import decimated_vessel

        return decimated_vessel(self.ingest.vertices, self.ingest.faces)

    def keep_vessel_display(self, shown: tuple[Any, Any, float]) -> None:
        """Keep ``shown``, :attr:`vessel_display` found from this data on a worker process, as its value here."""
        self.__dict__["vessel_display"] = shown

    @property
    def name(self) -> str:
        """The case's name."""
        return str(self.manifest.get("case", {}).get("name", self.build_dir.name))

    @property
    def export_q(self) -> list[float]:
        """The export q values, in the order of ``kinematics.json`` (one q for every link)."""
        return [float(pose["q"][0]) for pose in self.kinematics.document["poses"]]

    @property
    def link_count(self) -> int:
        """Number of links."""
        return self.kinematics.chain.count

    def mesh_file(self, q: float) -> Path | None:
        """The exported STL at ``q``, or None when that q was not exported as STL."""
        if self.export_summary is None:
            return None
        relative = mesh_name(q, "stl")
        file = self.build_dir / relative
        return file if relative in self.export_summary.get("meshes", {}) and file.is_file() else None


def load_build(build_dir: str | Path) -> BuildData:
    """Reload ``build_dir`` for the report.

    Raises
    ------
    InputDataError
        The folder, its manifest or a required stage's files are missing or unreadable.
    """
    root = Path(build_dir)
    fix = f"build it first: softdesign build CASE.yaml --out {root}"
    require_build(root)
    try:
        manifest = json.loads((root / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError) as err:
        raise InputDataError(f"{root / MANIFEST}: unreadable ({type(err).__name__}: {err}); {fix}") from err
    required = (layout.INGEST_SUMMARY, layout.INGEST_PATH, layout.BLEND_CURVES, layout.BLEND_SUMMARY, layout.LINKS,
                layout.KINEMATICS)
    check_manifest(root, manifest, fix)
    missing = [rel for rel in required if not (root / rel).is_file()]
    if missing:
        raise InputDataError(
            f"{root}: missing {', '.join(missing)}; the report needs ingest, blend, links and kinematics; {fix}"
        )
    try:
        ingest = load_ingest(root)
        blend = load_blend(root)
        kinematics = load_kinematics(root, load_links(root, blend))
        fit = load_fit(root) if _has(root, layout.FIT_SURFACE, layout.FIT_POINTS, layout.FIT_SUMMARY) else None
        export = load_export(root).summary if _has(root, layout.EXPORT_SUMMARY) else None
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as err:  # a truncated .npz is a BadZipFile
        raise InputDataError(
            f"{root}: a stage's kept files are unreadable ({type(err).__name__}: {err}); {fix} --force"
        ) from err
    return BuildData(root, manifest, ingest, blend, kinematics, fit, export)


def require_build(root: Path) -> None:
    """InputDataError unless ``root`` holds a manifest (checked before the report takes the folder's lock)."""
    if not (root / MANIFEST).is_file():
        raise InputDataError(f"{root}: not a build folder (no {MANIFEST}); "
                             f"build it first: softdesign build CASE.yaml --out {root}")


def _has(root: Path, *relative: str) -> bool:
    return all((root / rel).is_file() for rel in relative)

