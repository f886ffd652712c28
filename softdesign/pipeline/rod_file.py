"""``actuation/rod.json``: what the rod model needs, written by the build, read by ``softdesign pressure`` alone.

The actuation stage writes it for a case whose rod model applies (hoop reinforcement and a material law):

    format          ``softdesign rod model 1``
    case_sha256     sha256 of the resolved case (canonical JSON, :meth:`Case.resolved`): ``pressure`` refuses a
                    build made from other settings
    inputs          each input file's path (as the case names it) and sha256: ``pressure`` refuses a build made
                    from other files
    supply, backbone, modulus_kpa (E), thread_at (2,) mm
    stations        per station (base first): ds (rest length, mm), section, chamber (holds its section's
                    chamber), area (mm^2), first (2,) mm^3 and second (2, 2) mm^4 moments of the cross-section
                    less its cavities about the centreline (E A = modulus x area, E I = modulus x second),
                    force (c,) mm^2 (each channel's cavity area) and moment (c, 2) mm^3 (area x offset)
    single          design_pressure_kpa, each station's chamber distance_mm and angle (rad), the designed chain
                    (base2world (4, 4), w (n, 2) 1/mm, lengths (n,) mm)
    per_chamber     rest lengths (n,) mm, and at every q of the build's grid each section's best arc
                    (kappa, phi, length): the inverse's targets

Numbers are written as repr floats (JSON), so ``pressure`` evaluates exactly what the build did.  Reading it
imports numpy and the rod model only (no vtk, trimesh, scipy, mesher or stage).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.kinematics.rod import RodBody

if TYPE_CHECKING:
    from softdesign.config import Case

ROD_FILE = "actuation/rod.json"
FORMAT = "softdesign rod model 1"


def case_digest(case: Case) -> str:
    """sha256 of the resolved case's canonical JSON (the build's record of it)."""
    from softdesign.pipeline.store import canonical_json

    return hashlib.sha256(canonical_json(case.resolved()).encode("utf-8")).hexdigest()


def input_digests(case: Case) -> list[dict[str, str]]:
    """Each input file of the case: its path (as the case names it) and sha256."""
    from softdesign.pipeline.inputs import input_files
    from softdesign.pipeline.store import sha256_file

    return [{"path": case.resolved_path(p), "sha256": sha256_file(p)} for p in input_files(case)]


def body_document(body: RodBody, chamber: np.ndarray) -> dict[str, Any]:
    """The rod's stations and loads, JSON-ready."""
    return {"modulus_kpa": body.modulus_kpa, "backbone": body.backbone, "thread_at": body.thread_at.tolist(),
            "stations": {"ds": body.ds.tolist(), "section": body.section.tolist(), "chamber": chamber.tolist(),
                         "area": body.area.tolist(), "first": body.first.tolist(), "second": body.second.tolist(),
                         "force": body.force.tolist(), "moment": body.moment.tolist()}}


def rod_document(case: Case, body: RodBody, chamber: np.ndarray, extra: dict[str, Any]) -> dict[str, Any]:
    """The whole file: format, the case's and inputs' hashes, the body, and the supply's own part (``extra``)."""
    return {"format": FORMAT, "case_sha256": case_digest(case), "inputs": input_digests(case),
            **body_document(body, chamber), **extra}


def body_from(document: dict[str, Any]) -> RodBody:
    """The :class:`RodBody` of a rod file."""
    st = document["stations"]
    return RodBody(np.asarray(st["ds"], float), np.asarray(st["section"], np.int64), np.asarray(st["area"], float),
                   np.asarray(st["first"], float), np.asarray(st["second"], float), np.asarray(st["force"], float),
                   np.asarray(st["moment"], float), float(document["modulus_kpa"]), document["backbone"],
                   np.asarray(document["thread_at"], float))


def read_rod(case: Case, build_dir: Path, case_file: str) -> dict[str, Any]:
    """The build's rod file for ``case``, or ConfigError saying which command makes (or remakes) it."""
    path = Path(build_dir) / ROD_FILE
    remake = f"run `softdesign build {case_file}" + ("`" if build_dir == Path("build") / case.name
                                                     else f" --out {build_dir}`")
    if not path.is_file():
        raise ConfigError(f"pressure: no build of this case in {build_dir} ({ROD_FILE} not found): {remake} first "
                          "(pressure reads the rod model the build writes)")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as err:
        raise ConfigError(f"pressure: {path} cannot be read ({err}): {remake} again") from err
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise ConfigError(f"pressure: {path} is not a rod model this softdesign writes: {remake} again")
    if document.get("case_sha256") != case_digest(case):
        raise ConfigError(f"pressure: the build in {build_dir} was made from other settings than this case file's: "
                          f"{remake} again")
    if document.get("inputs") != input_digests(case):
        raise ConfigError(f"pressure: an input file of this case changed since the build in {build_dir}: {remake} "
                          "again")
    return document


def rod_of_unchanged_build(case_file: str | Path, out: Path | None) -> dict[str, Any] | None:
    """The build's rod file, without building the case's models, when nothing it came from has changed.

    That is when the build's manifest names this case file with the same text (``case_file``: its name and the
    sha256 of its text), every input still has the sha256 the manifest recorded, the softdesign that built it is
    this one, and the rod file is that build's (its ``case_sha256`` is the manifest's resolved case's).  None
    otherwise, whatever the reason (no build, an edit, even a comment's, a file that cannot be read): the caller
    then loads and validates the case and :func:`read_rod` says what is wrong.  Reads the case file, the manifest,
    the inputs (to hash them) and the rod file; imports yaml only when ``out`` is None (the case's ``name``).
    """
    from softdesign import __version__
    from softdesign.errors import SoftdesignError
    from softdesign.io.case_yaml import case_text_record, parse_case_yaml, read_case_text
    from softdesign.pipeline.store import canonical_json, sha256_file

    path = Path(case_file)
    try:
        text = read_case_text(path)
        build_dir = out if out is not None else Path("build") / _case_name(path, parse_case_yaml(path, text)[0])
        manifest, document = _json_of(build_dir / "manifest.json"), _json_of(build_dir / ROD_FILE)
        if (manifest.get("case_file") != case_text_record(path, text)
                or manifest.get("software", {}).get("softdesign") != __version__
                or not isinstance(document, dict) or document.get("format") != FORMAT
                or document.get("case_sha256") != hashlib.sha256(
                    canonical_json(manifest["case"]).encode("utf-8")).hexdigest()):
            return None
        base = path.resolve().parent
        if any(sha256_file(base / item["path"]) != item["sha256"] for item in manifest["inputs"]):
            return None
    except (SoftdesignError, OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return document


#: The largest manifest or rod file the quick path reads (the demo's are 190 and 50 kB); a bigger one is left to
#: the full path.
QUICK_READ_BYTES = 64 * 2**20


def _json_of(path: Path) -> Any:
    """A regular file's JSON (ValueError for anything else: a folder, a FIFO, a file over QUICK_READ_BYTES)."""
    import stat

    info = path.stat()
    if not stat.S_ISREG(info.st_mode) or info.st_size > QUICK_READ_BYTES:
        raise ValueError(f"{path} is not a rod model's file")
    return json.loads(path.read_text(encoding="utf-8"))


def _case_name(path: Path, raw: Any) -> str:
    """The case's ``name`` as :func:`softdesign.config.load_case` gives it (the file's stem by default)."""
    name = raw.get("name", path.stem) if isinstance(raw, dict) else None
    if not isinstance(name, str):
        raise ValueError("no name")
    return name

