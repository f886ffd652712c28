"""`--help` shows every option's whole help text and every command's whole first line (issue 19's plain help).

Typer's rich panels read ``[default: build/<name>]`` as a markup tag and dropped
it ("Build folder ."); click's plain help prints text as written.  These tests
compare the printed help with the help the options declare, so a return of
markup, or a command line cut to "...", fails them.
"""

from __future__ import annotations

import re

import pytest
import typer
from typer.testing import CliRunner

from softdesign.cli import app
from tests.cli.test_cli_conventions import ALL_COMMANDS

runner = CliRunner()


def _squeezed(text: str) -> str:
    """``text`` without whitespace, so that wrapping (also after a hyphen) does not matter."""
    return re.sub(r"\s+", "", text)


@pytest.mark.parametrize("name", sorted(ALL_COMMANDS))
def test_every_option_help_is_printed_whole(name):
    result = runner.invoke(app, [*name.split(), "--help"])
    assert result.exit_code == 0, result.output
    printed = _squeezed(result.output)
    declared = [param.help for param in ALL_COMMANDS[name].params if getattr(param, "help", None)]
    assert declared, name
    missing = [text for text in declared if _squeezed(text) not in printed]
    assert not missing, f"{name} --help lost: {missing}"


def test_the_bracketed_defaults_are_shown():
    output = runner.invoke(app, ["build", "--help"]).output
    assert "[default: build/<name>]" in output and "[default: the cores" in output


@pytest.mark.parametrize("group", [[], ["pcc"]])
def test_the_command_list_shows_each_first_paragraph_uncut(group):
    output = runner.invoke(app, [*group, "--help"]).output
    listing = _squeezed(output[output.index("Commands:"):])
    click_group = typer.main.get_command(app)
    for word in group:
        click_group = click_group.commands[word]
    for name, command in click_group.commands.items():
        line = command.short_help or ""
        assert line and not line.endswith("..."), name
        assert _squeezed(name + line) in listing, name
