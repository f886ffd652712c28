"""The order in which ``make test`` hands files to its workers: the longest first.

``make test`` gives whole files to its two workers (``--dist loadfile``) in the order of the collection
(``--no-loadscope-reorder``; xdist's own reorder puts the files with the most tests first, which left the slow
files of one or two tests, the FE sections, the README's commands, to the end, one worker running them while the
other had nothing left).  Started longest first, each worker takes the next file when it is done, and the two
finish within about the shortest file of each other (a greedy longest-first schedule).

Each file's seconds come from the last run on this machine (pytest's cache, ``.pytest_cache``: the summed
setup, call and teardown of its tests, updated for every file a run ran), else from :data:`RECORDED`
(tests/file_seconds.json: ``make test-seconds`` writes it from that cache after a full run).  A file in neither
counts as 0 seconds and goes after the others, in the collection's order.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import pytest

#: The committed seconds per file (what a fresh clone, e.g. CI, orders by).
RECORDED = Path(__file__).resolve().parents[1] / "file_seconds.json"
#: Where pytest's cache keeps the seconds of every test the runs on this machine ran (the last run of each).
CACHE_KEY = "softdesign/test_seconds"
#: That cache entry's file (pytest's cache layout: .pytest_cache/v/<key>), read by ``make test-seconds``.
CACHE_FILE = Path(__file__).resolve().parents[2] / ".pytest_cache" / "v" / CACHE_KEY


def file_of(nodeid: str) -> str:
    """The test file of a node id (``tests/x/test_y.py::test_z[p]`` -> ``tests/x/test_y.py``)."""
    return nodeid.split("::", 1)[0]


def per_file(test_seconds: dict[str, float]) -> dict[str, float]:
    """Seconds per file: the sum of its tests'."""
    files: dict[str, float] = defaultdict(float)
    for nodeid, value in test_seconds.items():
        files[file_of(nodeid)] += value
    return {name: round(value, 1) for name, value in sorted(files.items())}


def known_seconds(config: pytest.Config) -> dict[str, float]:
    """Seconds per file: the committed record, replaced file by file by this machine's cache (when it is on)."""
    seconds: dict[str, float] = json.loads(RECORDED.read_text(encoding="utf-8")) if RECORDED.is_file() else {}
    cache = getattr(config, "cache", None)
    if cache is not None:
        seconds.update(per_file(cache.get(CACHE_KEY, {})))
    return seconds


def longest_first(items: list[pytest.Item], seconds: dict[str, float]) -> None:
    """Reorder ``items`` in place: whole files, the longest first (stable: ties keep the collection's order)."""
    rank = {name: k for k, name in enumerate(dict.fromkeys(file_of(item.nodeid) for item in items))}
    items.sort(key=lambda item: (-seconds.get(file_of(item.nodeid), 0.0), rank[file_of(item.nodeid)]))


class SecondsRecorder:
    """Sums each test's reported seconds (setup, call, teardown) in a run; saves them to the cache at its end."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)

    def add(self, report: pytest.TestReport) -> None:
        self.seconds[report.nodeid] += report.duration

    def save(self, config: pytest.Config) -> None:
        cache = getattr(config, "cache", None)
        if cache is None or not self.seconds:
            return
        merged = dict(cache.get(CACHE_KEY, {}))
        merged.update({nodeid: round(value, 2) for nodeid, value in self.seconds.items()})
        cache.set(CACHE_KEY, dict(sorted(merged.items())))


def main() -> int:
    """``make test-seconds``: write :data:`RECORDED` from this machine's cache (after a full ``make test``)."""
    if not CACHE_FILE.is_file():
        print(f"no {CACHE_FILE}: run `make test` first (it records every test's seconds there)")
        return 2
    files = per_file(json.loads(CACHE_FILE.read_text(encoding="utf-8")))
    RECORDED.write_text(json.dumps(files, indent=1) + "\n", encoding="utf-8")
    print(f"{RECORDED}: {len(files)} files, {sum(files.values()):.0f} s in all")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
