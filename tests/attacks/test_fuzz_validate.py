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

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import DEMO

runner = CliRunner()
#: Each fuzz runs a few hundred validations: 5-9 s of CPU alone (11-19 s in a loaded make test-fast), so slow
#: (tests/conftest.py: about a second or more); make test runs them.
pytestmark = pytest.mark.slow

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


# Issue 45: the round-3 and round-4 blocks, and pcc reconstruct's tables.  The keys come from the schema itself
# (softdesign.cli.reference.case_keys), so a key a branch adds to one of these blocks (actuation.supply,
# .reinforcement, .backbone) is fuzzed as soon as the model has it; a new block is one more name in BLOCKS.

#: The blocks fuzzed key by key (dotted: a nested block is fuzzed whole and key by key).
BLOCKS = ("actuation", "design", "simulate", "export.volume_mesh", "export.mould", "material.custom")
#: How many case files of these blocks, and how many pcc tables.
BLOCK_CASES = 200
TABLES = 150
#: Values these blocks' keys name or users type for them, beside SCALARS.
BLOCK_SCALARS = [
    "'yes'", "3.0", "3", "0.1", "0.2", "5", "37", "512", "single", "per_chamber", "hoop", "none", "free",
    "inextensible", "sweep", "ftetwild", "neo-hookean", "yeoh", "ecoflex-00-30", "tpu-85a", "\"a\\x1b[2Jb\"",
    "{kind: yeoh, c1_kpa: 1e-300, c2_kpa: 0, c3_kpa: 0}", "[1, 1]", "[0, 1.5]", "[2, 1]",
]


def _block_keys() -> list[str]:
    from softdesign.cli.reference import case_keys
    from softdesign.config import Case

    return [key for key, _, _ in case_keys(Case) if any(key == b or key.startswith(b + ".") for b in BLOCKS)]


def _block_value(rng: random.Random) -> str:
    return rng.choice(BLOCK_SCALARS) if rng.random() < 0.5 else _value(rng)


def block_case_text(rng: random.Random, keys: list[str]) -> str:
    """The demo case with one to three keys of the round-3/4 blocks set to generated YAML (often still valid)."""
    import yaml

    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    if rng.random() < 0.5:
        case["actuation"] = {}  # simulate and the chambers' keys are read with it
    raw: dict[str, str] = {}
    for n, key in enumerate(rng.sample(keys, rng.randint(1, 3))):
        *parents, last = key.split(".")
        holder = case
        for part in parents:
            child = holder.get(part)
            holder = holder.setdefault(part, {}) if child is None else child
            if not isinstance(holder, dict):
                break
        else:
            holder[last] = f"__value_{n}__"
            raw[f"__value_{n}__"] = _block_value(rng)
    text = yaml.safe_dump(case, sort_keys=False, width=10_000)
    for marker, value in raw.items():
        text = text.replace(marker, value)
    return text


def test_generated_round_3_and_4_blocks_never_end_in_a_traceback(tmp_path):
    rng = random.Random(SEED + 9)
    keys = _block_keys()
    assert {k.split(".")[0] for k in keys} >= {"actuation", "design", "simulate", "export", "material"}
    path = tmp_path / "case.yaml"
    codes: dict[int, int] = {}
    for index in range(BLOCK_CASES):
        text = block_case_text(rng, keys)
        path.write_text(text, encoding="utf-8")
        result = runner.invoke(app, ["validate", str(path)])
        escaped = result.exception if not isinstance(result.exception, SystemExit) else None
        assert escaped is None, f"case {index}:\n{text}\n{type(escaped).__name__}: {escaped}"
        assert result.exit_code in (0, 2), f"case {index}: exit {result.exit_code}\n{text}\n{result.output}"
        assert "\x1b" not in result.output, f"case {index}: a control character reached the terminal"
        codes[result.exit_code] = codes.get(result.exit_code, 0) + 1
    assert codes.get(2, 0) > BLOCK_CASES // 2 and codes.get(0, 0) > 0, codes  # most refused, some pass through


#: Cells of a generated readings or actuation table.
CELLS = ["1", "10", "10.5", "0", "-1", "nan", "inf", "-inf", "1e300", "1e-300", "", "abc", "1:30", "0x10", "3", "2",
         "90", "210", "330", "120", "\"1,2\"", "9" * 400]


def table_text(rng: random.Random) -> str:
    """A readings CSV (time + 3 lengths per section) or an actuation table, rows from CELLS or plausible values."""
    if rng.random() < 0.5:
        sections = rng.choice([1, 1, 2, 3, 0])
        header = ["t"] + [f"l{s}{c}" for s in range(1, sections + 1) for c in (1, 2, 3)]
        rows = [[str(k) if rng.random() < 0.8 else rng.choice(CELLS)]
                + [f"{10 + rng.random():.3f}" if rng.random() < 0.8 else rng.choice(CELLS) for _ in header[1:]]
                for k in range(rng.randint(0, 12))]
    else:
        header = ["q", "section", "chamber", "angle_deg", "distance_mm", "length_mm"]
        rows = []
        for q in range(rng.randint(0, 3)):
            for section in range(1, rng.randint(1, 3) + 1):
                for chamber, angle in ((1, 90), (2, 210), (3, 330)):
                    row = [str(q / 2), str(section), str(chamber), str(angle), "3", f"{10 + rng.random():.3f}"]
                    if rng.random() < 0.15:
                        row[rng.randrange(len(row))] = rng.choice(CELLS)
                    rows.append(row)
    if rng.random() < 0.1 and rows:
        rows[rng.randrange(len(rows))].append("extra")
    return "\n".join(",".join(r) for r in [header, *rows]) + "\n"


def test_generated_pcc_tables_never_end_in_a_traceback(tmp_path):
    rng = random.Random(SEED + 45)
    path = tmp_path / "table.csv"
    codes: dict[int, int] = {}
    for index in range(TABLES):
        text = table_text(rng)
        path.write_text(text, encoding="utf-8")
        args = ["pcc", "reconstruct", str(path), "--shapes-dir", str(tmp_path / "shapes")]
        result = runner.invoke(app, args + (["--d", "3"] if text.startswith("t") else []))
        escaped = result.exception if not isinstance(result.exception, SystemExit) else None
        assert escaped is None, f"table {index}:\n{text}\n{type(escaped).__name__}: {escaped}"
        assert result.exit_code in (0, 2), f"table {index}: exit {result.exit_code}\n{text}\n{result.output}"
        codes[result.exit_code] = codes.get(result.exit_code, 0) + 1
    assert codes.get(2, 0) > 0 and codes.get(0, 0) > 0, codes
