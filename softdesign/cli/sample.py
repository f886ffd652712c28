"""`softdesign sample OUT_DIR`: the project's sample vessel, VMTK-style (centerline .vtp, surface .stl)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from softdesign.cli.common import run_guarded


def sample(out_dir: Annotated[Path, typer.Argument(help="Folder to write the sample vessel into.")]) -> None:
    """Write the project's sample vessel (centerline .vtp and surface .stl), VMTK-style."""

    def action() -> None:
        from softdesign.samples.files import write_sample

        for path in write_sample(out_dir):
            typer.echo(f"wrote {path}")

    run_guarded(action)
