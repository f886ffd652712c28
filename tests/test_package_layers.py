"""The package's house rules, read from its source: homes at the root, layers that import downward, no cycles.

Every ``import`` statement counts, wherever it stands (module level, inside a function, under
``TYPE_CHECKING``): a late import still ties two modules together. Complements
``tests/geometry/test_layers.py``, which imports each geometry module in a fresh interpreter.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "softdesign"

#: STYLE.md's tree: at the root only the errors, the array conventions and the cohort summary (the case
#: file, the size bounds and the material presets are packages of their own).
ROOT_MODULES = {"__init__", "__main__", "errors", "types", "cohort"}

#: Layer -> what it must never import. The numeric core and the meshes never reach the edges above them;
#: the case file's models never reach the pipeline that runs them.
FORBIDDEN = {
    "geometry": ("io", "pipeline", "cli", "report", "regression", "cohort", "kinematics", "fitting", "meshing"),
    "kinematics": ("io", "pipeline", "cli", "report", "regression", "cohort"),
    "fitting": ("io", "pipeline", "cli", "report", "regression", "cohort"),
    "meshing": ("io", "pipeline", "cli", "report", "regression", "cohort", "mechanics"),
    "mechanics": ("io", "pipeline", "cli", "report", "regression", "cohort"),
    # the material math under both the meshes and the finite elements (issue 45): numpy and the array types only
    "continuum": ("io", "pipeline", "cli", "report", "regression", "cohort", "geometry", "kinematics", "fitting",
                  "meshing", "mechanics", "config", "limits", "materials", "centerline", "samples"),
    # meshing's rooms, by what they make: the body, then the chambers cut into it, then the mould and the volume
    # mesh made around or of the chambered body (neither of which needs the other)
    "meshing.body": ("meshing.chambers", "meshing.mould", "meshing.volume_mesh"),
    "meshing.chambers": ("meshing.mould", "meshing.volume_mesh"),
    "meshing.mould": ("meshing.volume_mesh",),
    "meshing.volume_mesh": ("meshing.mould",),
    "config": ("pipeline", "cli", "report", "regression", "cohort"),
    "limits": ("pipeline", "cli", "report", "regression", "cohort"),
    "materials": ("pipeline", "cli", "report", "regression", "cohort"),
}


def _modules() -> dict[str, Path]:
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


MODULES = _modules()


def _imports(path: Path) -> set[str]:
    """The softdesign modules (or packages) ``path`` imports, by any import statement anywhere in it."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
    return {name for name in names if name in MODULES}


@functools.cache
def import_graph() -> dict[str, set[str]]:
    """Each module -> the softdesign modules it imports: every source parsed (about 0.8 s of CPU), once, when a test
    first asks, not at collection (where every xdist worker paid it, whichever worker ran this file)."""
    return {name: _imports(path) - {name} for name, path in MODULES.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_cycle_and_passes_a_chain():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_no_two_modules_import_each_other_even_late():
    assert _cycles(import_graph()) == []


def test_the_root_holds_only_its_named_modules():
    loose = sorted(p.stem for p in PACKAGE.glob("*.py") if p.stem not in ROOT_MODULES)
    assert loose == [], f"modules loose at the package root, give them a home: {loose}"
    for home in ("config", "limits", "materials"):
        assert (PACKAGE / home / "__init__.py").is_file()


@pytest.mark.parametrize("layer", sorted(FORBIDDEN))
def test_a_layer_imports_nothing_above_it(layer):
    def within(name: str, homes: tuple[str, ...]) -> bool:
        return any(name == home or name.startswith(f"{home}.") for home in homes)

    above = tuple(f"softdesign.{name}" for name in FORBIDDEN[layer])
    home = (f"softdesign.{layer}",)
    wrong = sorted(f"{module} -> {target}" for module, targets in import_graph().items() if within(module, home)
                   for target in targets if within(target, above))
    assert wrong == []


#: meshing's rooms; the modules beside them (checks, topology, solids, tessellation, ...) are what every room shares.
MESHING_ROOMS = ("body", "chambers", "mould", "volume_mesh")


def test_meshings_shared_modules_import_none_of_its_rooms():
    for room in MESHING_ROOMS:
        assert (PACKAGE / "meshing" / room / "__init__.py").is_file()
    graph = import_graph()
    shared = [name for name in graph if name.count(".") == 2 and name.startswith("softdesign.meshing.")
              and name.rsplit(".", 1)[1] not in MESHING_ROOMS]
    assert "softdesign.meshing.topology" in shared  # the selection is not empty
    rooms = tuple(f"softdesign.meshing.{room}" for room in MESHING_ROOMS)
    wrong = sorted(f"{module} -> {target}" for module in shared for target in graph[module]
                   if any(target == r or target.startswith(f"{r}.") for r in rooms))
    assert wrong == []
