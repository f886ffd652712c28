"""The README a newcomer starts from: short, opening on the two commands, and every command in it runs (issue 34)."""

from __future__ import annotations

import re
import shlex

import pytest

from tests.helpers.paths import REPO
from tests.helpers.shared_builds import DEMO_BUILD, run_once, workspace

README = (REPO / "README.md").read_text(encoding="utf-8")
#: "At most about 150 lines" (issue 34): the reference is in docs/.
MAX_README_LINES = 150


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
def test_every_command_of_the_readme_runs(tmp_path_factory):
    # in the run's shared workspace (copies of configs/ and data/): tests/e2e/test_one_story.py and the report
    # tests read the builds of the same commands, each run once for all of them (tests/helpers/shared_builds.py)
    commands = readme_commands()
    assert len(commands) >= 6
    # what `make demo` does first: the sample case built with its report
    steps = [list(DEMO_BUILD)] + [shlex.split(c)[1:] for c in commands]
    for args in steps:
        done = run_once(tmp_path_factory, *args)
        assert done.returncode == 0, f"softdesign {' '.join(args)}:\n{done.stderr[-3000:]}"
        assert "Traceback" not in done.stderr
    folder = workspace(tmp_path_factory)
    assert (folder / "build" / "demo" / "report" / "index.html").is_file()
    assert (folder / "build" / "actuator" / "actuation.csv").is_file()
    assert (folder / "build" / "demo-designed" / "design" / "summary.json").is_file()
