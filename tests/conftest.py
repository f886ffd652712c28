"""Shared fixtures: the real VMTK data beside the checkout, the attack tests' prior build (helpers: tests/helpers/).

How the suite runs: ``make test`` is ``pytest -n auto --dist loadfile --no-loadscope-reorder --durations=15``
(pytest-xdist): one worker process per core, each taking whole test files, the longest first (the order below,
tests/helpers/schedule.py).  So that a test stays right and fast there:

* Write only under ``tmp_path`` (one test) or ``tmp_path_factory.mktemp(...)`` (a shared fixture): each worker
  has its own base folder.  Never under the checkout (``build/``, ``data/``, ``tests/``) nor a fixed /tmp path;
  a subprocess that runs ``softdesign`` gets ``--out`` under ``tmp_path``.  The one exception is the browser
  test's screenshots (build/test-artifacts/browser/, names of their own, one file writes them).
* A build several tests only read is built once: a ``scope="module"`` fixture (the file's tests all run in the
  same worker) or, when several files read it, once for the whole run in the folder the workers share
  (tests/helpers/shared_builds.py: the README's commands and the demo build made by the first, under a lock the
  others wait on).  A test that changes such a build copies it first (see ``out`` below: a copy of
  ``prior_build``; ``demo_build_copy``).  ``functools.cache`` on a module-level builder does the same for
  in-memory results (meshes, solves).
* A build a test makes passes ``--jobs 1`` (``jobs=1`` in-process) unless the test is about the build's pool: the
  two workers already fill the cores, and a pool of two forked on top costs about 1-2 s of CPU a build (the pool
  is tested by tests/pipeline/test_parallel*.py, test_report_jobs and the attacks on workers).  The README's
  commands run as written, on one core (shared_builds.run_once): their default ``--jobs`` is then 1.
* No fixed ports, no lock files but shared_builds' own, no environment changes outside ``monkeypatch``; a child
  process gets its own ``env=`` copy.
* Mark a test ``@pytest.mark.slow`` when it takes about a second or more (``make test-fast`` leaves them out); a
  study that takes minutes does not belong in the suite: record its expensive end in a reference under tests/
  and re-derive it with a make target, as the refinement study does (tests/helpers/refinement_study.py,
  ``make study``), or run its short form and keep the long one for a target (``make study-property``).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from softdesign.pipeline.parallel import one_blas_thread

# One OpenBLAS thread per test process, as the command line asks for itself before numpy loads (softdesign.cli.main;
# an xdist worker inherits it from the controller, which loads this file first): the commands a test runs in its own
# process (CliRunner, build_through) ran with OpenBLAS's thread per core, which wait on the cores the two workers
# already fill.  The design stage's small dense solves paid most: tests/pipeline/test_design_stage.py took 14.7 s of
# CPU, 8.7 s with one thread.  Before the helpers below import numpy (OpenBLAS reads the variable when it loads).
one_blas_thread()

from tests.helpers.attacks import BUILD_TIMEOUT_S, demo_case, run_limited  # noqa: E402
from tests.helpers.paths import AORTA_DIR  # noqa: E402
from tests.helpers.schedule import SecondsRecorder, known_seconds, longest_first  # noqa: E402
from tests.helpers.shared_builds import made_once, shared_root  # noqa: E402

_RECORDER = SecondsRecorder()


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Whole files, the longest first (every worker collects the same order: the controller hands files out in it)."""
    longest_first(items, known_seconds(config))


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    _RECORDER.add(report)


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Each test's seconds into pytest's cache, by the process that saw them all (not an xdist worker)."""
    if not hasattr(session.config, "workerinput"):
        _RECORDER.save(session.config)


@pytest.fixture(scope="session")
def aorta_dir() -> Path:
    """../shared/data/vmtk-aorta, or skip (a user's clone has no shared/ beside it)."""
    if not AORTA_DIR.is_dir():
        pytest.skip(f"real VMTK data not found at {AORTA_DIR} (CI has ../shared beside the checkout)")
    return AORTA_DIR


def _build_prior(folder: Path) -> None:
    folder.mkdir()
    result = run_limited("build", str(demo_case(folder)), "--out", str(folder / "build"), timeout=BUILD_TIMEOUT_S)
    assert result.returncode == 0, result.stderr


@pytest.fixture(scope="session")
def prior_build(tmp_path_factory) -> Path:
    """The coarse demo built once per run, for every worker (in a child under the memory budget): the build an
    attack must leave as it was.  Only read: each attack works on its copy (``out``)."""
    return made_once(shared_root(tmp_path_factory), "prior", _build_prior) / "build"


@pytest.fixture
def out(prior_build, tmp_path) -> Path:
    """A copy of the prior build for one attack."""
    target = tmp_path / "build"
    shutil.copytree(prior_build, target)
    return target
