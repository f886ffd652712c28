"""The reinforcement threads' data: every entry loads with its sources, in newtons and millimetres."""

from __future__ import annotations

import pytest

from softdesign.materials.threads import NEWTON_PER_UNIT, thread_presets

#: 1 lbf in newtons (NIST SP 811: 4.448222 N), to the digits written in the test.
LBF_N = 4.448222


def test_every_thread_has_a_positive_load_and_says_where_its_numbers_come_from():
    threads = thread_presets()
    assert threads, "softdesign/data/threads.yaml lists no thread"
    for name, t in threads.items():
        assert t.breaking_load_n > 0 and t.diameter_mm > 0 and t.modulus_gpa > 0, name
        assert "breaking load:" in t.source and "diameter:" in t.source, name
        # a diameter this project did not read in a document says so
        assert "unverified" in t.source, name


def test_the_kevlar_69_load_is_the_source_s_23_lbf():
    assert thread_presets()["kevlar-69"].breaking_load_n == pytest.approx(23 * LBF_N, rel=1e-6)
    assert NEWTON_PER_UNIT["lbf"] == pytest.approx(LBF_N, rel=1e-6)
