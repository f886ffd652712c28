"""`softdesign sample OUT_DIR [--force]`: the project's sample vessel, VMTK-style (centerline .vtp, surface .stl)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from softdesign.cli.common import run_guarded
from softdesign.errors import ConfigError

SampleForceOpt = Annotated[bool, typer.Option("--force", help="Replace sample files already in OUT_DIR.")]


def sample(
    out_dir: Annotated[Path, typer.Argument(help="Folder to write the sample vessel into.")],
    force: SampleForceOpt = False,
) -> None:
    """Write the project's sample vessel (centerline .vtp and surface .stl), VMTK-style."""

    def action() -> None:
        from softdesign.samples.files import CENTERLINE, SAMPLE_SURFACE, write_sample

        if out_dir.exists() and not out_dir.is_dir():
            raise ConfigError(f"{out_dir}: is a file, expected a folder to write the sample into; give another folder")
        there = [out_dir / name for name in (CENTERLINE, SAMPLE_SURFACE) if (out_dir / name).exists()]
        if there and not force:
            names = " and ".join(str(p) for p in there)
            raise ConfigError(
                f"{names}: already there, and softdesign sample does not overwrite files; "
                "give --force to replace them, or another folder"
            )
        try:
            written = write_sample(out_dir)
        except OSError as err:
            where = err.filename or out_dir
            reason = err.strerror or err
            raise ConfigError(f"{where}: cannot write the sample ({reason}); give a writable folder") from err
        for path in written:
            typer.echo(f"wrote {path}")

    run_guarded(action)
