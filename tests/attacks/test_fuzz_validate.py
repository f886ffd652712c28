"""Issue 36: a few hundred generated case files through ``softdesign validate``: never a traceback.

A seeded generator (same files on every run) writes case files a careless or
hostile user might: the real sections and keys with values of every YAML
kind (numbers huge, tiny, negative, non-finite, base 60, long integers,
strings, lists, mappings, null, booleans), unknown keys, keys given twice,
anchors and aliases (also an alias inside itself), merge keys, broken syntax,
and sometimes the demo's real input files so that validation goes past the
file checks.  ``validate`` runs in process (CliRunner, no subprocess per
file), and every answer must be exit 0 or 2 with no exception escaping.
"""

from __future__ import annotations

import random

from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import DEMO

runner = CliRunner()

#: How many case files, and the generator's seed (fixed: the same files every run).
CASES = 300
SEED = 36

SECTIONS = {
    "final": ["centerline", "surface", "path", "inlet", "reverse", "surface_units"],
    "initial": ["kind", "length_mm", "radius_mm", "surface", "bend_radius_mm", "bend_plane_deg", "centerline", "path"],
    "resample": ["spacing_mm", "count", "smoothing_mm", "end_straight_mm"],
    "links": ["count", "breaks", "length_mm"],
    "fit": ["knot_spacing_mm", "angular_intervals", "smoothing", "holdout_folds", "outlier_factor", "end_margin_mm",
            "end_cut"],
    "export": ["q", "frames", "offset_mm", "wall_mm", "port_mm", "formats", "spacing_mm", "angular_count",
               "split_regions", "mould", "volume_mesh"],
    "material": ["name", "max_stretch", "min_stretch", "min_wall_mm"],
}
TOP = ["name", "units", "frames", "blend", "intermediate", "bogus"]
SCALARS = [
    "0", "1", "-1", "4", "0.5", "1e308", "-1e308", "1e-308", "1e400", ".nan", ".inf", "-.inf", "1:30", "190:20:30.15",
    "9" * 4400, "0x1F", "0o17", "1_000", "null", "~", "true", "no", "''", "auto", "stl", "rmf", "'a b'", "é",
    "straight", "arc", "file", "mm", "m", "2001-01-01", "!!binary aGVsbG8=", "[]", "{}", "[0, 0.5, 1]", "[1, 2, 3]",
]


def _value(rng: random.Random, depth: int = 0) -> str:
    roll = rng.random()
    if roll < 0.6 or depth > 2:
        return rng.choice(SCALARS)
    if roll < 0.8:
        return "[" + ", ".join(_value(rng, depth + 1) for _ in range(rng.randint(0, 4))) + "]"
    keys = rng.sample(sum(SECTIONS.values(), []), rng.randint(0, 3))
    return "{" + ", ".join(f"{k}: {_value(rng, depth + 1)}" for k in keys) + "}"


def _section(rng: random.Random, name: str) -> list[str]:
    lines = [f"{name}:"]
    if rng.random() < 0.1:
        lines.append("  <<: *anchor")
    for key in rng.sample(SECTIONS[name], rng.randint(0, len(SECTIONS[name]))):
        value = _value(rng)
        if name == "final" and key in ("centerline", "surface") and rng.random() < 0.6:
            value = str((DEMO.parent / f"../data/demo/{key}.{'vtp' if key == 'centerline' else 'stl'}").resolve())
        lines.append(f"  {key}: {value}")
        if rng.random() < 0.05:
            lines.append(f"  {key}: {_value(rng)}")  # the key again
    return lines


def _demo_lines() -> list[str]:
    """The demo case, inputs absolute, one ``section: {key: value, ...}`` line per section."""
    import yaml

    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    return [yaml.safe_dump({k: v}, default_flow_style=True, width=10_000).strip() for k, v in case.items()]


def _mutated_demo(rng: random.Random) -> str:
    """The demo with one key of one section set to a generated value (often still valid)."""
    lines = _demo_lines()
    name = rng.choice([n for n in SECTIONS if n != "material"])
    entry = f"{name}: {{{rng.choice(SECTIONS[name])}: {_value(rng)}}}"
    index = next((i for i, line in enumerate(lines) if line.startswith(f"{{{name}:")), None)
    if index is None or name == "final":
        lines.append(entry if name != "final" else f"{{export: {{q: {_value(rng)}}}}}")
    else:
        lines[index] = "{" + entry + "}"
    return "\n".join(line[1:-1] if line.startswith("{") else line for line in lines) + "\n"


def case_text(rng: random.Random) -> str:
    """One generated case file: a mutated demo (a third) or one written from scratch."""
    if rng.random() < 0.35:
        return _mutated_demo(rng)
    lines = ["name: fuzz"] if rng.random() < 0.9 else []
    if rng.random() < 0.2:
        lines.append(f"base: &anchor {{{rng.choice(SECTIONS['fit'])}: {rng.choice(SCALARS)}}}")
    for name in rng.sample(list(SECTIONS), rng.randint(1, len(SECTIONS))):
        lines += _section(rng, name)
    for key in rng.sample(TOP, rng.randint(0, 2)):
        lines.append(f"{key}: {_value(rng)}")
    if rng.random() < 0.05:
        lines.append("loop: &a [*a]")
    if rng.random() < 0.05:
        lines.insert(rng.randrange(len(lines) + 1), rng.choice(["  : :", "- [", "\t", "key: 'open", "%YAML 9.9"]))
    return "\n".join(lines) + "\n"


def test_generated_case_files_never_end_in_a_traceback(tmp_path):
    rng = random.Random(SEED)
    path = tmp_path / "case.yaml"
    codes: dict[int, int] = {}
    for index in range(CASES):
        text = case_text(rng)
        path.write_text(text, encoding="utf-8")
        result = runner.invoke(app, ["validate", str(path)])
        escaped = result.exception if not isinstance(result.exception, SystemExit) else None
        assert escaped is None, f"case {index}:\n{text}\n{type(escaped).__name__}: {escaped}"
        assert result.exit_code in (0, 2), f"case {index}: exit {result.exit_code}\n{text}\n{result.output}"
        codes[result.exit_code] = codes.get(result.exit_code, 0) + 1
    assert codes.get(2, 0) > CASES // 2  # most generated files are wrong, and refused
    assert codes.get(0, 0) > 0  # and some valid ones reach the end of validation
