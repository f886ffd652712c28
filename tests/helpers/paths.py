"""Where the tests find the repository's own files and the shared real data."""

from __future__ import annotations

from pathlib import Path

#: The checkout (tests/helpers/ is two levels below it).
REPO = Path(__file__).resolve().parents[2]
#: The sample case.
DEMO = REPO / "configs" / "demo.yaml"
#: ../shared/data beside the checkout (CI puts it there; a user's clone may not have it).
SHARED_DATA = REPO.parent / "shared" / "data"
AORTA_DIR = SHARED_DATA / "vmtk-aorta"
