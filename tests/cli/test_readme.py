"""The README a newcomer starts from: short, opening on the two commands, and every command in it runs (issue 34)."""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys

import pytest

from tests.helpers.paths import REPO

README = (REPO / "README.md").read_text(encoding="utf-8")
#: "At most about 150 lines" (issue 34): the reference is in docs/.
MAX_README_LINES = 150
#: The CLI as the README's `.venv/bin/softdesign` runs it, in this test's interpreter.
CLI = [sys.executable, "-c", "import sys; from softdesign.cli import main; sys.argv[0] = 'softdesign'; main()"]


def readme_commands() -> list[str]:
    """Every `.venv/bin/softdesign ...` line of the README's sh blocks, in order, without its comment."""
    blocks = re.findall(r"```sh\n(.*?)```", README, flags=re.S)
    lines = [line.split("#", 1)[0].strip() for block in blocks for line in block.splitlines()]
    return [line for line in lines if line.startswith(".venv/bin/softdesign ")]


def test_the_readme_is_short_and_opens_on_the_two_commands():
    assert len(README.splitlines()) <= MAX_README_LINES
    first = re.search(r"```sh\n(.*?)```", README, flags=re.S)
    assert first is not None
    assert [line.split("#")[0].strip() for line in first.group(1).splitlines()] == ["make demo", "make test"]
    for page in re.findall(r"\]\((docs/[^)]+)\)", README):
        assert (REPO / page).is_file(), page
    assert "Zou et al. [2]" in README and "seeds/" not in README  # the papers cited, not files it does not hold
    assert "init" in README and "design" in README and "mould" in README


@pytest.mark.slow
def test_every_command_of_the_readme_runs(tmp_path):
    shutil.copytree(REPO / "configs", tmp_path / "configs")
    shutil.copytree(REPO / "data", tmp_path / "data")
    commands = readme_commands()
    assert len(commands) >= 6
    # what `make demo` does first: the sample case built with its report
    steps = [["build", "configs/demo.yaml", "--report"]] + [shlex.split(c)[1:] for c in commands]
    for args in steps:
        done = subprocess.run([*CLI, *args], cwd=tmp_path, capture_output=True, text=True, timeout=900,
                              stdin=subprocess.DEVNULL)
        assert done.returncode == 0, f"softdesign {' '.join(args)}:\n{done.stderr[-3000:]}"
        assert "Traceback" not in done.stderr
    assert (tmp_path / "build" / "demo" / "report" / "index.html").is_file()
    assert (tmp_path / "build" / "actuator" / "actuation.csv").is_file()
    assert (tmp_path / "build" / "demo-designed" / "design" / "summary.json").is_file()
