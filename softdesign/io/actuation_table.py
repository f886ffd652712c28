"""Read a build's ``actuation.csv`` (one row per q, section, chamber) as encoder readings.

The table is written by :mod:`softdesign.pipeline.stages.actuation`: columns
``q, export, section, chamber, angle_deg, distance_mm, length_mm, ...``.  Here it
becomes, per q (in file order), the (sections, 3) chamber lengths, with each
section's first chamber angle and distance, checked: three chambers per section
120 degrees apart, one distance per section, the same sections at every q.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softdesign.errors import InputDataError

#: The columns that make a CSV an actuation table (the rest are read but not needed).
REQUIRED = ("q", "section", "chamber", "angle_deg", "distance_mm", "length_mm")
#: How far apart (degrees) a section's chambers may be from 120 degrees (the table carries repr floats).
ANGLE_TOL_DEG = 1e-6


class ActuationReadings(NamedTuple):
    """The table as readings: q (n,), lengths (n, k, 3) mm, first angle (k,) rad, distance (k,) mm."""

    q: np.ndarray
    lengths: np.ndarray
    first_angle: np.ndarray
    distance_mm: np.ndarray


def is_actuation_header(header: list[str]) -> bool:
    """True when ``header`` names every column of :data:`REQUIRED`."""
    names = {h.strip() for h in header}
    return all(c in names for c in REQUIRED)


def first_row(path: Path) -> list[str]:
    """The first row of a CSV file, or [] when it is missing, unreadable or empty (its reader says why)."""
    try:
        with path.open(encoding="utf-8", newline="") as handle:
            return next(csv.reader(handle), [])
    except (OSError, UnicodeDecodeError, csv.Error):
        return []


def _number(path: Path, line: int, name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputDataError(f"{path} line {line}: {name} '{text}' is not a finite number; fix the row")
    return value


def read_actuation_table(path: Path, max_length_mm: float, max_sections: int) -> ActuationReadings:
    """The readings of an actuation table, lengths and distances at most ``max_length_mm``, sections at most
    ``max_sections`` (the bounds of encoder readings, so that a table is held to what a readings file is).

    Raises
    ------
    InputDataError
        A missing column, a bad number, a length, distance or section beyond its bound, chambers not 1..3 at
        120 degrees, or sections that differ between q.
    """
    rows = list(csv.reader(io.StringIO(path.read_text(encoding="utf-8"))))
    header = [h.strip() for h in rows[0]]
    col = {name: header.index(name) for name in REQUIRED}
    table: dict[float, dict[int, dict[int, tuple[float, float, float]]]] = {}
    for line, values in enumerate(rows[1:], start=2):
        if not values:
            continue
        if len(values) != len(header):
            raise InputDataError(f"{path} line {line}: {len(values)} columns, expected {len(header)} as in the header")
        q, angle, distance, length = (_number(path, line, n, values[col[n]])
                                      for n in ("q", "angle_deg", "distance_mm", "length_mm"))
        section, chamber = (int(_number(path, line, n, values[col[n]])) for n in ("section", "chamber"))
        if (chamber not in (1, 2, 3) or not 1 <= section <= max_sections or not 0.0 < length <= max_length_mm
                or not 0.0 < distance <= max_length_mm):
            raise InputDataError(f"{path} line {line}: section {section} chamber {chamber} length {length:g} mm "
                                 f"distance {distance:g} mm; expected chambers 1-3, sections 1 to {max_sections}, "
                                 f"lengths and distances > 0 and at most {max_length_mm:g} mm")
        table.setdefault(q, {}).setdefault(section, {})[chamber] = (angle, distance, length)
    return _assemble(path, table)


def _assemble(path: Path, table: dict[float, dict[int, dict[int, tuple[float, float, float]]]]) -> ActuationReadings:
    if not table:
        raise InputDataError(f"{path}: no rows; expected one row per q, section and chamber")
    first_q = next(iter(table))
    sections = sorted(table[first_q])
    if sections != list(range(1, len(sections) + 1)):
        raise InputDataError(f"{path}: q={first_q:g} has sections {sections}, expected 1..{len(sections)}")
    angles, distances = [], []
    for s in sections:
        chambers = table[first_q][s]
        if sorted(chambers) != [1, 2, 3]:
            raise InputDataError(f"{path}: q={first_q:g} section {s} has chambers {sorted(chambers)}, expected 1, 2, 3")
        a = np.array([chambers[j][0] for j in (1, 2, 3)])
        steps = np.mod(np.diff(a), 360.0)
        if np.any(np.abs(steps - 120.0) > ANGLE_TOL_DEG) or len({chambers[j][1] for j in (1, 2, 3)}) != 1:
            raise InputDataError(f"{path}: section {s}: chambers at {a.tolist()} deg, distances "
                                 f"{[chambers[j][1] for j in (1, 2, 3)]} mm; Zou et al.'s model needs three "
                                 "chambers 120 deg apart at one distance")
        angles.append(np.deg2rad(a[0]))
        distances.append(chambers[1][1])
    lengths = np.empty((len(table), len(sections), 3))
    for n, (q, by_section) in enumerate(table.items()):
        if sorted(by_section) != sections or any(sorted(by_section[s]) != [1, 2, 3] for s in sections):
            raise InputDataError(f"{path}: q={q:g} does not list chambers 1-3 of sections 1..{len(sections)} as "
                                 f"q={first_q:g} does")
        for s in sections:
            lengths[n, s - 1] = [by_section[s][j][2] for j in (1, 2, 3)]
    return ActuationReadings(np.array(list(table)), lengths, np.array(angles), np.array(distances))
