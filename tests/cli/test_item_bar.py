"""The per-mesh bar of a build (issue 17): drawn on a terminal in the stage line's place, nothing elsewhere."""

from __future__ import annotations

import io

from rich.console import Console

from softdesign.cli.item_bar import build_progress


class _Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def _export_on(stage_line, listener, q_values):
    stage_line("[5/9] export: running")
    listener("export", 0, len(q_values), "")
    for i, q in enumerate(q_values, start=1):
        listener("export", i, len(q_values), f"mesh q = {q:g}")
    stage_line("[6/9] export: done in 1.00 s")


def test_a_terminal_sees_every_mesh_counted_then_the_stage_line_again():
    screen = _Terminal()
    console = Console(file=screen, force_terminal=True, width=100)
    q_values = [0, 0.25, 0.5, 0.75, 1]
    with build_progress(stream=screen, console=console) as (stage_line, listener):
        assert listener is not None
        _export_on(stage_line, listener, q_values)
    drawn = screen.getvalue()
    assert "[5/9] export: 5 to make" in drawn and "0/5" in drawn
    for i, q in enumerate(q_values, start=1):
        assert f"[5/9] export: mesh q = {q:g} done" in drawn and f"{i}/5" in drawn
    bar_gone = drawn.rindex("\x1b[2K")  # the transient bar erases its line ...
    assert drawn.index("6/9 export: done in 1.00 s") > bar_gone  # ... and the stage line is drawn after it
    assert drawn.rindex("\x1b[?25l") < drawn.rindex("\x1b[?25h")  # the cursor the bar hid is shown again


def test_an_early_end_takes_the_bar_away():
    screen = _Terminal()
    console = Console(file=screen, force_terminal=True, width=100)
    try:
        with build_progress(stream=screen, console=console) as (stage_line, listener):
            stage_line("[5/9] export: running")
            listener("export", 0, 3, "")
            listener("export", 1, 3, "mesh q = 0")
            raise RuntimeError("a mesh failed")
    except RuntimeError:
        pass
    drawn = screen.getvalue()
    assert "1/3" in drawn and "\x1b[?25h\r\x1b[1A\x1b[2K" in drawn[drawn.index("1/3"):]  # cursor shown, bar erased


def test_json_or_a_pipe_gets_no_bar_and_plain_stage_lines():
    for stream, enabled in ((_Terminal(), False), (io.StringIO(), True)):
        with build_progress(enabled=enabled, stream=stream) as (stage_line, listener):
            assert listener is None
            stage_line("[5/9] export: running")
        assert "\x1b" not in stream.getvalue()
    piped = io.StringIO()
    with build_progress(stream=piped) as (stage_line, _):
        stage_line("[5/9] export: running")
    assert piped.getvalue() == "[5/9] export: running\n"
