"""Issue 44, item 4: the steps that take seconds show progress on a terminal (a pseudo-terminal here).

The coarse demo with chambers and a mould: on a terminal the actuation's walls per q, the mould's two steps and
the feasibility's skin per q each draw the build's item bar (as export's meshes do, tests/e2e/test_export_progress.py,
which also checks that a pipe gets none and that the bar changes no byte); the report draws its own bar.
"""

from __future__ import annotations

import re

import pytest

from tests.e2e.test_export_progress import _on_a_terminal
from tests.helpers.attacks import demo_case

pytestmark = pytest.mark.slow


def test_slow_steps_draw_their_bars_on_a_terminal(tmp_path):
    case = demo_case(tmp_path, actuation={},
                     export={"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0, "mould": {}})
    code, stdout, screen = _on_a_terminal("build", str(case), "--out", str(tmp_path / "tty"), "--jobs", "1",
                                          "--report")
    assert code == 0, screen
    assert re.search(r"\[\d+/\d+\] actuation: walls at q = 1 done .*\d+/\d+", screen), screen
    assert re.search(r"\[\d+/\d+\] mould: the parts done .*1/2", screen), screen
    assert re.search(r"\[\d+/\d+\] feasibility: skin at q = 1 done .*\d+/\d+", screen), screen
    assert re.search(r"report: \S+ \(\d+\.\d s\)", screen), screen  # the report's bar names each part
    # the bars are transient: what stays on stdout ends with the verdict and the build folder
    assert stdout.splitlines()[-1] == f"build folder: {tmp_path / 'tty'}"
