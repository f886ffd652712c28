"""Shared fixtures: the real VMTK data beside the checkout (helpers live in tests/helpers/)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers.paths import AORTA_DIR


@pytest.fixture(scope="session")
def aorta_dir() -> Path:
    """../shared/data/vmtk-aorta, or skip (a user's clone has no shared/ beside it)."""
    if not AORTA_DIR.is_dir():
        pytest.skip(f"real VMTK data not found at {AORTA_DIR} (CI has ../shared beside the checkout)")
    return AORTA_DIR
