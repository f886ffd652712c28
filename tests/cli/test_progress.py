"""The progress bar: drawn on a terminal with each part's name, nothing at all elsewhere."""

from __future__ import annotations

import io

from rich.console import Console

from softdesign.cli.progress import part_progress


def test_a_terminal_sees_each_part_and_a_pipe_sees_nothing(capsys):
    out = io.StringIO()
    console = Console(file=out, force_terminal=True, width=100)
    with part_progress("report", enabled=True, console=console) as tick:
        assert tick is not None
        tick("morph.png", 1.25)
        tick("the 3D view", 0.5)
    drawn = out.getvalue()
    assert "report: the 3D view (0.5 s)" in drawn
    with part_progress("report") as silent:  # pytest's captured stderr is not a terminal
        assert silent is None
    assert capsys.readouterr().err == ""
