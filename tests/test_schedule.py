"""The suite's own schedule: test files handed to the workers longest first (tests/helpers/schedule.py)."""

from __future__ import annotations

import json
from dataclasses import dataclass

from tests.helpers import schedule


@dataclass
class Item:
    nodeid: str


def test_files_go_longest_first_whole_and_in_their_own_order():
    ids = ["a.py::t1", "a.py::t2", "b.py::t1", "c.py::t1[x]", "c.py::t1[y]", "d.py::t1", "e.py::t1"]
    items = [Item(i) for i in ids]
    schedule.longest_first(items, {"c.py": 9.0, "a.py": 2.0, "e.py": 2.0, "b.py": 0.5})  # type: ignore[arg-type]
    # c first, then a and e (a tie: the collection's order), then b, then d (unknown: 0 s, last)
    assert [i.nodeid for i in items] == ["c.py::t1[x]", "c.py::t1[y]", "a.py::t1", "a.py::t2", "e.py::t1",
                                        "b.py::t1", "d.py::t1"]


def test_a_files_seconds_are_its_tests_and_the_cache_replaces_the_record(monkeypatch, tmp_path):
    assert schedule.per_file({"a.py::t1": 1.25, "a.py::t2[p::q]": 2.5, "b.py::t": 0.5}) == {"a.py": 3.8, "b.py": 0.5}
    record = tmp_path / "file_seconds.json"
    record.write_text(json.dumps({"a.py": 100.0, "b.py": 7.0}))
    monkeypatch.setattr(schedule, "RECORDED", record)

    class Cache:
        def get(self, key, default):
            assert key == schedule.CACHE_KEY
            return {"a.py::t1": 3.0}

    class Config:
        cache = Cache()

    assert schedule.known_seconds(Config()) == {"a.py": 3.0, "b.py": 7.0}  # type: ignore[arg-type]
