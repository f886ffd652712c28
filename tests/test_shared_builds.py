"""What the workers of one run share (tests/helpers/shared_builds.py): a folder made once, under a lock."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import pytest

from tests.helpers.shared_builds import made_once


def _make_slowly(folder: Path) -> None:
    with (folder.parent / "makes.log").open("a") as log:  # one line per make, beside the shared folder
        log.write(f"{folder.name}\n")
    folder.mkdir()
    (folder / "made").write_text("")
    time.sleep(0.5)  # long enough for the other process to ask while this one makes


def _ask(root: str) -> list[str]:
    return sorted(p.name for p in made_once(Path(root), "thing", _make_slowly).iterdir())


@pytest.mark.slow  # two interpreters started (about 3 s on a busy machine)
def test_two_processes_asking_at_once_get_one_build(tmp_path):
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        seen = pool.map(_ask, [str(tmp_path)] * 2)
    assert seen == [["made"], ["made"]]  # each read the finished folder, the mark not in it
    assert (tmp_path / "makes.log").read_text() == "thing\n"  # made once: the other waited and read it
    assert (tmp_path / "thing.done").is_file()


def test_a_failed_make_leaves_no_mark_and_the_next_asker_makes_it_again(tmp_path):
    def failing(folder: Path) -> None:
        folder.mkdir()
        (folder / "half").write_text("")
        raise RuntimeError("the build failed")

    with pytest.raises(RuntimeError, match="the build failed"):
        made_once(tmp_path, "thing", failing)
    assert not (tmp_path / "thing.done").exists()
    assert _ask(str(tmp_path)) == ["made"]  # made again; the failed attempt's leftovers are gone
    assert (tmp_path / "makes.log").read_text() == "thing\n"
