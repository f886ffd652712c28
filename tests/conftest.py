"""Shared fixtures: the real VMTK data beside the checkout, the attack tests' prior build (helpers: tests/helpers/)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.helpers.attacks import BUILD_TIMEOUT_S, demo_case, run_limited
from tests.helpers.paths import AORTA_DIR


@pytest.fixture(scope="session")
def aorta_dir() -> Path:
    """../shared/data/vmtk-aorta, or skip (a user's clone has no shared/ beside it)."""
    if not AORTA_DIR.is_dir():
        pytest.skip(f"real VMTK data not found at {AORTA_DIR} (CI has ../shared beside the checkout)")
    return AORTA_DIR


@pytest.fixture(scope="session")
def prior_build(tmp_path_factory) -> Path:
    """The coarse demo built once (in a child under the memory budget): the build an attack must leave as it was."""
    folder = tmp_path_factory.mktemp("prior")
    result = run_limited("build", str(demo_case(folder)), "--out", str(folder / "build"), timeout=BUILD_TIMEOUT_S)
    assert result.returncode == 0, result.stderr
    return folder / "build"


@pytest.fixture
def out(prior_build, tmp_path) -> Path:
    """A copy of the prior build for one attack."""
    target = tmp_path / "build"
    shutil.copytree(prior_build, target)
    return target
