"""`make bench`'s start-up figures: wall and CPU time of fresh processes, each what it claims to be (issue 19)."""

from __future__ import annotations

import sys

from tests.e2e.test_bench import bench  # noqa: F401  (the fixture: pipelines/bench.py as a module)

#: A child that spins until it has used this much CPU, and one that sleeps this long (seconds).
BUSY_S = 0.2
ASLEEP_S = 0.4


def test_cpu_time_is_the_child_s_user_and_system_time_not_its_wall_time(bench):  # noqa: F811
    spin = f"import time\nstart = time.process_time()\nwhile time.process_time() - start < {BUSY_S}: pass"
    wall, cpu = bench.median_runs([sys.executable, "-c", spin], repeats=3)
    assert cpu >= BUSY_S and wall >= cpu * 0.9  # ... cpu is at most wall on one thread (clock granularity aside)
    wall, cpu = bench.median_runs([sys.executable, "-c", f"import time; time.sleep({ASLEEP_S})"], repeats=3)
    assert wall >= ASLEEP_S and cpu < ASLEEP_S / 2  # asleep, the child used the start-up's CPU only


def test_the_startup_lines_show_the_cpu_time_beside_the_wall_time(bench):  # noqa: F811
    lines = bench.startup_lines({"help_s": 0.5, "help_cpu_s": 0.14, "validate_s": 0.4, "validate_cpu_s": 0.33})
    help_line = next(line for line in lines if "--help" in line)
    validate_line = next(line for line in lines if "validate" in line)
    assert "0.50 s" in help_line and "MISSED" in help_line and "(cpu 0.14 s)" in help_line
    assert "0.40 s" in validate_line and " met " in validate_line and "(cpu 0.33 s)" in validate_line
