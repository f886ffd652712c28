"""The commented case file ``softdesign init`` writes for a user's own vessel files.

Every key it sets is one a newcomer is likely to change; the comments say
what each does and list what the files hold (each path with its length, its
radius at the inlet and at the end, where it leaves the others and the
opening it ends at), so the file is its own first documentation.  ``path``
is the main vessel by :data:`~softdesign.geometry.path_survey.MAIN_PATH_RULE`
(the path of largest lumen volume), and the comment names the alternatives.
Paths are written relative to the case file's folder, as the case file
reads them, each as a double-quoted YAML string (:func:`yaml_string`): a
folder named ``Patient #12`` or holding ``: ``, braces, a leading ``- `` or
a newline reads back as written, never as a comment or another key.
:func:`paths_read_back` checks that on the text before it is written.  The first line names the case file's JSON Schema
(``softdesign schema``) for editors that complete and check YAML
(``yaml-language-server``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from softdesign.geometry.path_survey import MAIN_PATH_RULE
from softdesign.pipeline.inspect_inputs import Inspection

#: The file beside the case that holds the case file's JSON Schema (written by ``init``).
SCHEMA_FILE = "softdesign-case.schema.json"
#: The material a new case is judged against: the commonest silicone of soft actuators, so a first build
#: gives a feasible / not-feasible verdict.
DEFAULT_MATERIAL = "ecoflex-00-30"
#: About one link (section) per this much path length, between 1 and MAX_INIT_LINKS.
LINK_LENGTH_MM = 25.0
MAX_INIT_LINKS = 8


def init_case_text(inspection: Inspection, case_path: Path, name: str) -> str:
    """The case file's text (see the module notes).

    Parameters
    ----------
    inspection : what the files hold
    case_path : where the case file will be written (paths are made relative to its folder)
    name : the case's name (a slug: letters, digits, ``-``, ``_``)
    """
    from softdesign.types import UNIT_SCALE_TO_MM

    unit = inspection.units
    scale = UNIT_SCALE_TO_MM[unit]
    main = inspection.main_path
    links = min(MAX_INIT_LINKS, max(1, round(main.length * scale / LINK_LENGTH_MM)))
    folder = case_path.parent
    centerline = "auto" if inspection.centerline is None else yaml_string(_relative(inspection.centerline, folder))
    inlet = ", ".join(f"{v:.6g}" for v in inspection.inlet)
    lines = [
        f"# yaml-language-server: $schema={SCHEMA_FILE}",
        f"# Written by softdesign init from {yaml_string(inspection.surface.name)}"
        + ("" if inspection.centerline is None else f" and {yaml_string(inspection.centerline.name)}")
        + ". Build it with: softdesign build " + case_path.name,
        *_units_comment(inspection),
        f"name: {name}",
        f"units: {unit}                 # the unit of the input files (and of final.inlet)",
        "final:                      # the patient's shape, q = 1",
        f"  centerline: {centerline}" + ("   # extracted from the surface at ingest" if centerline == "auto" else ""),
        f"  surface: {yaml_string(_relative(inspection.surface, folder))}",
        f"  path: {inspection.main}                   # which path the actuator follows; proposed: the main vessel, "
        + MAIN_PATH_RULE,
        *_path_comments(inspection),
        f"  inlet: [{inlet}]   # l = 0, where the actuator is mounted: the end nearest this point",
        "initial: {kind: straight}   # the insertion shape, q = 0",
        "resample: {spacing_mm: 0.5, smoothing_mm: 0.1}",
        f"links: {{count: {links}}}          # sections of the actuator (about one per {LINK_LENGTH_MM:g} mm)",
        "fit: {knot_spacing_mm: 1.5, angular_intervals: 24}",
        "export: {q: [0, 0.5, 1], formats: [stl]}   # meshes at these q; add mould: {} for a casting mould",
        f"material: {{name: {DEFAULT_MATERIAL}}}    # the stretch and wall limits the design is judged against",
    ]
    return "\n".join(lines) + "\n"


def yaml_string(text: str) -> str:
    """``text`` as one double-quoted YAML scalar on one line (JSON's escapes, which YAML reads the same)."""
    return json.dumps(text, ensure_ascii=False)


def expected_paths(inspection: Inspection, case_path: Path) -> dict[str, str]:
    """``{"centerline": ..., "surface": ...}`` as :func:`init_case_text` means the case's ``final`` to hold."""
    folder = case_path.parent
    centerline = "auto" if inspection.centerline is None else _relative(inspection.centerline, folder)
    return {"centerline": centerline, "surface": _relative(inspection.surface, folder)}


def paths_read_back(data: Any) -> dict[str, Any]:
    """The ``final`` paths of a parsed case (what a build would read), for comparison with :func:`expected_paths`."""
    final = data.get("final") if isinstance(data, dict) else None
    final = final if isinstance(final, dict) else {}
    return {key: final.get(key) for key in ("centerline", "surface")}


def _relative(path: Path, folder: Path) -> str:
    return Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix()


def _units_comment(inspection: Inspection) -> list[str]:
    if inspection.guess is None:
        return [f"# units: {inspection.units}, as given to init"]
    evidence = [f"#   {line}" for line in inspection.guess.evidence]
    return [f"# units: {inspection.units}, guessed from the sizes:", *evidence]


def _path_comments(inspection: Inspection) -> list[str]:
    """The rule's alternatives, then every path of the files in words (``softdesign.pipeline.path_text``)."""
    from softdesign.pipeline.path_text import alternatives_line, path_lines
    from softdesign.types import UNIT_SCALE_TO_MM

    alternatives = alternatives_line(inspection.facts, inspection.main)
    head = [] if alternatives is None else [f"  #   {alternatives}; the files hold:"]
    lines = path_lines(inspection.facts, inspection.units, UNIT_SCALE_TO_MM[inspection.units], inspection.main)
    return head + [f"  #   {line}" for line in lines]
