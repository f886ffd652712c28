"""The bounds of the `softdesign pcc` commands' numbers, each stated and refused (exit 2) before any work.

Why these values (Zou et al.'s sections are a few cm long, a few mm from the backbone, sampled at tens of points):

* a cable length of at most :data:`MAX_LENGTH_MM` (100 m): beyond it the arcs' trigonometry loses every digit
  and ``--lengths 1e308`` gave NaN poses;
* at most :data:`MAX_SECTIONS` sections, as a design has at most :data:`~softdesign.limits.MAX_LINKS` links;
* a readings file of at most :data:`MAX_READINGS_BYTES` (64 MB, about a million rows of three sections) and
  :data:`MAX_READINGS_ROWS` rows, counted before a row is parsed (8 million short rows of a 64 MB file took
  4.3 GB and 218 s, a million rows 3.1 GB and 194 s; 100,000 rows at 20 points per section, the backbone
  bound below, peak at 1.0 GB and 31 s), an actuation table too; at most :data:`MAX_REJECTED_NOTES` rejected
  rows are told on stderr (all of them are in rejected.csv);
* at most :data:`MAX_BACKBONE_POINTS` backbone samples written in all (rows x sections x points per section):
  each holds a 4x4 pose, its frame and arc length, about 250 bytes while built, 500 MB at the bound (1000 rows
  of 1000 sections tried 2.5 GiB);
* ``--points-per-section`` at most :data:`MAX_POINTS_PER_SECTION` and ``pcc design --samples`` at most
  :data:`MAX_DESIGN_SAMPLES` (100 million samples peaked at 3.1 GB).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from softdesign.errors import ConfigError, InputDataError
from softdesign.io.case_yaml import file_kind
from softdesign.limits import MAX_LINKS

#: Longest cable length a reading or ``--lengths`` may give, mm.
MAX_LENGTH_MM = 100_000.0
#: Most sections a readings file or ``--lengths`` may have.
MAX_SECTIONS = MAX_LINKS
#: Largest readings CSV, bytes.
MAX_READINGS_BYTES = 64_000_000
#: Most rows (readings or actuation-table rows) a file may have, counted before parsing: 100 readings a second for
#: over 16 minutes.
MAX_READINGS_ROWS = 100_000
#: Most rejected rows told one by one on stderr; the rest are counted (rejected.csv lists them all).
MAX_REJECTED_NOTES = 20
#: Most backbone samples ``pcc reconstruct`` writes in all (accepted rows x sections x points per section).
MAX_BACKBONE_POINTS = 2_000_000
#: Most backbone samples per arc (``pcc reconstruct --points-per-section``).
MAX_POINTS_PER_SECTION = 10_000
#: Most backbone samples per link of ``pcc design --samples``.
MAX_DESIGN_SAMPLES = 10_000


def check_backbone_points(where: str, rows: int, sections: int, points_per_section: int) -> None:
    """InputDataError when ``rows x sections x points_per_section`` exceeds MAX_BACKBONE_POINTS."""
    total = rows * sections * points_per_section
    if total > MAX_BACKBONE_POINTS:
        raise InputDataError(
            f"{where}: {rows} accepted row(s) x {sections} section(s) x {points_per_section} points per section "
            f"= {total:,} backbone samples, above the bound of {MAX_BACKBONE_POINTS:,}; lower --points-per-section "
            "or split the readings into several files"
        )


def check_readings_file(path: Path) -> None:
    """InputDataError unless ``path`` is a regular file (a FIFO would hang the read) within MAX_READINGS_BYTES."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        raise InputDataError(f"{path}: readings file not found; check the path") from None
    except OSError as err:
        raise InputDataError(f"{path}: cannot reach the readings file ({err.strerror}); check the path") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputDataError(f"{path}: is {file_kind(info.st_mode)}, not a regular file; expected the readings CSV: "
                             "give its path (save a stream to a file first)")
    if info.st_size > MAX_READINGS_BYTES:
        raise InputDataError(f"{path}: {info.st_size:,} bytes, above the bound of {MAX_READINGS_BYTES:,} for a "
                             "readings file; split the readings into several files")


def check_readings_rows(path: Path) -> None:
    """InputDataError when ``path`` (within MAX_READINGS_BYTES) has more than MAX_READINGS_ROWS rows and a header."""
    lines = 0
    try:
        with path.open("rb") as handle:
            for chunk in iter(lambda: handle.read(1 << 20), b""):
                lines += chunk.count(b"\n")
    except OSError as err:
        raise InputDataError(f"{path}: cannot read the readings file ({err.strerror})") from None
    if lines > MAX_READINGS_ROWS + 1:
        raise InputDataError(f"{path}: {lines:,} lines, above the bound of {MAX_READINGS_ROWS:,} rows (and a header) "
                             "for a readings file; split the readings into several files")


def check_shapes_dir(path: Path) -> None:
    """ConfigError when ``--shapes-dir`` names a file (or lies under one); else the folder is made."""
    blocker = next((p for p in (path, *path.parents) if p.exists() and not p.is_dir()), None)
    if blocker is not None:
        raise ConfigError(f"--shapes-dir {path}: {blocker} is a file, expected a folder (made if missing); "
                          "give a folder's path")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise ConfigError(f"--shapes-dir {path}: cannot make the folder ({err.strerror}); give a writable folder"
                          ) from None
