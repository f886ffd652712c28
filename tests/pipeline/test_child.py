"""A function run in a child process: its answer, and a crash, a hang or an exception as a clear MeshError."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.pipeline.child import HUGE_PAGES, run_in_child

FIX = "try a coarser size"


def double(values: np.ndarray) -> np.ndarray:
    return 2.0 * values


def abort() -> None:
    os.abort()


def sleep(seconds: float) -> None:
    time.sleep(seconds)


def allocate(gib: float) -> int:
    return int(np.ones(int(gib * 2**30 // 8)).size)


def write_stray_file() -> str:
    Path("stray.txt").write_text("native libraries write such files")
    return os.getcwd()


def environment_variable(name: str) -> str | None:
    return os.environ.get(name)


def raise_value_error() -> None:
    raise ValueError("no tetrahedra")


def test_the_answer_comes_back():
    values = np.arange(12.0).reshape(4, 3)
    np.testing.assert_array_equal(run_in_child(double, (values,), 60.0, "doubling", FIX), 2.0 * values)


def test_a_crash_is_named_with_its_signal():
    with pytest.raises(MeshError, match=r"doubling crashed \(killed by signal SIGABRT\) before answering; try a"):
        run_in_child(abort, (), 60.0, "doubling", FIX)


def test_a_hang_is_stopped_at_the_timeout():
    with pytest.raises(MeshError, match=r"sleeping did not finish within 1 s and was stopped; try a coarser size"):
        run_in_child(sleep, (600.0,), 1.0, "sleeping", FIX)


def test_an_exception_in_the_child_is_reported_by_type_and_message():
    with pytest.raises(MeshError, match="raising failed: ValueError: no tetrahedra; try a coarser size"):
        run_in_child(raise_value_error, (), 60.0, "raising", FIX)


def test_the_timeout_must_be_positive():
    with pytest.raises(ValueError, match="timeout_s must be > 0"):
        run_in_child(double, (np.zeros(1),), 0.0, "doubling", FIX)


def test_an_allocation_beyond_the_memory_limit_is_reported():
    # 4 GiB asked of a child limited to 1 GiB of address space (the interpreter and numpy need about 0.15)
    with pytest.raises(MeshError, match=r"allocating failed: it ran out of memory \(the child's limit of 1.00 GiB\)"):
        run_in_child(allocate, (4.0,), 60.0, "allocating", FIX, memory_bytes=2**30)
    # within the limit the same function answers
    assert run_in_child(allocate, (0.01,), 60.0, "allocating", FIX, memory_bytes=2**30) == 2**30 // 100 // 8


def test_files_the_child_writes_in_its_working_folder_go_with_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scratch = Path(run_in_child(write_stray_file, (), 60.0, "writing", FIX))
    assert scratch != tmp_path and not scratch.exists() and not (tmp_path / "stray.txt").exists()


def test_a_child_starts_with_the_environment_asked_and_the_parent_keeps_its_own(monkeypatch):
    monkeypatch.delenv("GLIBC_TUNABLES", raising=False)
    seen = run_in_child(environment_variable, ("GLIBC_TUNABLES",), 60, "a child", "nothing", environment=HUGE_PAGES)
    assert seen == "glibc.malloc.hugetlb=1" and "GLIBC_TUNABLES" not in os.environ
    assert run_in_child(environment_variable, ("GLIBC_TUNABLES",), 60, "a child", "nothing") is None
    # a setting the user made is kept, the huge pages after it; the parent's is as it was
    monkeypatch.setenv("GLIBC_TUNABLES", "glibc.malloc.arena_max=2")
    seen = run_in_child(environment_variable, ("GLIBC_TUNABLES",), 60, "a child", "nothing", environment=HUGE_PAGES)
    assert seen == "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1"
    assert os.environ["GLIBC_TUNABLES"] == "glibc.malloc.arena_max=2"
