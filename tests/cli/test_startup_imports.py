"""The command line starts without the heavy libraries: they are imported by the functions that use them (issue 19).

Each check runs the command in a fresh interpreter (a test process has them
all imported already) and lists the modules it loaded.  No timing: what is
checked is what gets imported, which is what the start-up time follows.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from softdesign.io.format_names import MESH_FORMATS
from softdesign.io.formats import FORMATS
from tests.helpers.paths import DEMO, REPO

#: Slow to import (about 0.2 to 1 s each with what they pull in); none is needed to parse, validate or print help.
HEAVY = ("vtk", "vtkmodules", "scipy", "trimesh", "manifold3d", "matplotlib")
#: Not needed to print help or check a case either: numpy (about 0.1 s), and rich with markdown_it (typer's rich
#: help panels, about 0.13 s of the 0.26 s `--help` took with them; the help is click's plain text).
LIGHT_BUT_UNNEEDED = ("numpy", "rich", "markdown_it", "pygments")
UNNEEDED = (*HEAVY, *LIGHT_BUT_UNNEEDED)

#: Runs the command line on argv, then writes the top-level modules it loaded, as JSON, on a last line of stderr.
_CHILD = """
import json, sys
from softdesign.cli import main
sys.argv[:] = ["softdesign", *sys.argv[1:]]
try:
    main()
except SystemExit as stop:
    code = stop.code
else:
    code = 0
sys.stderr.write("\\nMODULES " + json.dumps(sorted({name.partition(".")[0] for name in sys.modules})) + "\\n")
sys.exit(code)
"""


def _modules_loaded(*args: str) -> tuple[int, set[str], str]:
    """Exit code, top-level modules loaded and stdout + stderr of ``softdesign ARGS`` in a fresh interpreter."""
    result = subprocess.run(
        [sys.executable, "-c", _CHILD, *args], capture_output=True, text=True, cwd=REPO, timeout=120,
        stdin=subprocess.DEVNULL,
    )
    line = next(text for text in result.stderr.splitlines() if text.startswith("MODULES "))
    return result.returncode, set(json.loads(line.removeprefix("MODULES "))), result.stdout + result.stderr


@pytest.mark.parametrize("args", [["--help"], ["build", "--help"], ["pcc", "design", "--help"], ["check", "--help"]])
def test_help_imports_no_heavy_library_nor_numpy(args):
    code, modules, stdout = _modules_loaded(*args)
    assert code == 0 and "Usage" in stdout
    assert modules.isdisjoint(UNNEEDED), sorted(modules.intersection(UNNEEDED))


def test_validate_checks_the_whole_schema_then_opens_the_inputs():
    """Issue 29: validate opens every input file, after the schema; issue 46: a binary STL with numpy alone (its
    corners, tests/io/test_stl_corners.py), the surround check without scipy (a few hundred points), the
    centerline's .vtp without vtk (tests/io/test_vtp_xml.py)."""
    code, modules, stdout = _modules_loaded("validate", str(DEMO))
    assert code == 0 and "valid" in stdout and "VTK XML PolyData" in stdout
    assert "STL: 8455 points, 16906 triangles" in stdout  # the surface is read, not only found
    assert "pydantic" in modules and "yaml" in modules  # the schema is checked, not skipped
    # the centerline is opened with the build's reader, which reads a VMTK .vtp without vtk (io/vtp_xml.py)
    assert modules.isdisjoint(HEAVY), sorted(modules & set(HEAVY))


def test_validate_still_refuses_a_bad_key_in_a_fresh_interpreter(tmp_path):
    case = tmp_path / "case.yaml"
    case.write_text(DEMO.read_text().replace("angular_intervals: 24", "angular_intervals: 24, knots: 3"))
    code, modules, output = _modules_loaded("validate", str(case))
    assert code == 2 and "knots" in output and "Traceback" not in output
    assert modules.isdisjoint(HEAVY)


def test_the_light_format_names_are_the_registry_s_writable_formats():
    assert MESH_FORMATS == tuple(name for name, f in FORMATS.items() if f.encode is not None)
