"""What a first-time user relies on across commands: -o is the build folder, the reference documents it all."""

from __future__ import annotations

import re
import typing

import typer
from pydantic import BaseModel
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import Case
from tests.helpers.paths import REPO

#: The full reference (docs/reference.md); the README is the short introduction (tests/cli/test_readme.py).
README = (REPO / "docs" / "reference.md").read_text(encoding="utf-8")
runner = CliRunner()


def schema_keys(model: type[BaseModel], prefix: str = "") -> list[str]:
    """Every key of the case schema, dotted (``export.port_mm``), sections included."""
    keys = []
    for name, field in model.model_fields.items():
        keys.append(prefix + name)
        nested = [t for a in (field.annotation, *typing.get_args(field.annotation)) for t in (a, *typing.get_args(a))]
        for sub in {t for t in nested if isinstance(t, type) and issubclass(t, BaseModel)}:
            keys += schema_keys(sub, f"{prefix}{name}.")
    return keys


def commands(group, prefix: str = "") -> dict:
    """Every command of the app by its full name (``pcc forward``); typer's own click core, so no click import."""
    found = {}
    for name, command in group.commands.items():
        if hasattr(command, "commands"):
            found.update(commands(command, f"{prefix}{name} "))
        else:
            found[prefix + name] = command
    return found


ALL_COMMANDS = commands(typer.main.get_command(app))


def test_every_case_key_is_in_the_readme():
    section = README[README.index("## The case file"): README.index("## Layout")]
    keys = schema_keys(Case)
    assert len(keys) > 40  # the walk reached the nested sections
    missing = [k for k in keys if not re.search(rf"\b{re.escape(k.rsplit('.', 1)[-1])}\b", section)]
    assert not missing, f"case keys not documented in README's case file section: {missing}"


def test_every_command_is_in_the_readme():
    assert {"build", "pose", "report", "check", "pcc design", "pcc reconstruct"} <= ALL_COMMANDS.keys()
    missing = [name for name in ALL_COMMANDS if not re.search(rf"softdesign [a-z|]*\b{name}\b", README)]
    assert not missing, f"commands not shown in README: {missing}"


def test_out_and_its_short_form_are_the_build_folder_in_every_command():
    with_out = []
    for name, command in ALL_COMMANDS.items():
        for param in command.params:
            if "-o" in param.opts or "--out" in param.opts:
                assert set(param.opts) == {"--out", "-o"}, (name, param.opts)
                assert "Build folder" in (param.help or ""), (name, param.help)
                with_out.append(name)
    assert {"build", "ingest", "links", "kinematics", "export", "pose", "pcc design"} <= set(with_out)


def test_pose_with_a_mesh_file_after_out_says_how_to_write_the_mesh(tmp_path):
    case = REPO / "configs" / "demo.yaml"
    result = runner.invoke(app, ["pose", str(case), "--q", "1", "--output", str(tmp_path / "a.stl"),
                                 "-o", str(tmp_path / "pose.stl")])
    assert result.exit_code == 2
    assert "is the build folder in every softdesign command" in result.output and "--output" in result.output
    assert not (tmp_path / "pose.stl").exists() and not (tmp_path / "a.stl").exists()


def test_reconstruct_writes_into_shapes_dir_and_has_no_o(tmp_path):
    readings = tmp_path / "r.csv"
    readings.write_text("t,l1,l2,l3\n0,50,50,50\n1,49,50,51\n")
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir", str(tmp_path / "s")])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in (tmp_path / "s").iterdir()) == ["backbones.vtp", "rejected.csv", "tips.csv"]
    old = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "-o", str(tmp_path / "t")])
    assert old.exit_code == 2 and "No such option" in old.output and not (tmp_path / "t").exists()


def test_readme_documents_what_check_and_validate_refuse_or_warn_about():
    from softdesign.geometry.plausibility import PLAUSIBLE_RADIUS_MM
    from softdesign.meshing.checks import MIN_ANGULAR_COUNT

    for text in ("--failures-only", "different cases", "frames: frenet", "resample.end_straight_mm",
                 f"`export.angular_count` below {MIN_ANGULAR_COUNT}", f"at least {MIN_ANGULAR_COUNT}",
                 f"median inscribed radius {PLAUSIBLE_RADIUS_MM[0]:g} to {PLAUSIBLE_RADIUS_MM[1]:g} mm"):
        assert text in README, f"README does not say {text!r}"
