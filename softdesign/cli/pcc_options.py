"""Options of the `softdesign pcc` commands: ``--lengths`` and ``--d``, declared and parsed.

Parsing raises :class:`~softdesign.errors.ConfigError` naming the option and the fix.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated

import typer

from softdesign.cli.common import distances_from_text, finite_number
from softdesign.cli.pcc_bounds import MAX_LENGTH_MM, MAX_SECTIONS
from softdesign.errors import ConfigError

if TYPE_CHECKING:  # numpy is imported where it is used: `softdesign --help` starts without it
    import numpy as np

LengthsOpt = Annotated[
    str,
    typer.Option(
        "--lengths",
        help='Encoder lengths in mm, three per section, sections separated by ";": "120,123,124;125,123,121".',
        show_default=False,
    ),
]
DOpt = Annotated[
    str,
    typer.Option(
        "--d", help='Distance of the cables from the backbone, mm: one value ("15") or one per section ("15,14,13").',
        show_default=False,
    ),
]


def lengths_from_text(text: str) -> np.ndarray:
    """Parse ``--lengths`` ("l11,l12,l13;l21,l22,l23") into a (k, 3) array, mm, each > 0."""
    import numpy as np

    fix = 'give three lengths in mm per section, sections separated by ";", e.g. "120,123,124;125,123,121"'
    sections = [part for part in text.split(";") if part.strip()]
    if not sections:
        raise ConfigError(f"--lengths: no lengths given; {fix}")
    if len(sections) > MAX_SECTIONS:
        raise ConfigError(f"--lengths: {len(sections)} sections, above the bound of {MAX_SECTIONS}; {fix}")
    rows = []
    for i, part in enumerate(sections, start=1):
        values = part.split(",")
        if len(values) != 3:
            raise ConfigError(
                f"--lengths: section {i} has {len(values)} length(s) ('{part.strip()}'), expected 3; {fix}"
            )
        row = [finite_number(v, f"--lengths: section {i} cable {j}", fix) for j, v in enumerate(values, start=1)]
        for j, value in enumerate(row, start=1):
            if not 0 < value <= MAX_LENGTH_MM:
                raise ConfigError(f"--lengths: section {i} cable {j} is {value:g} mm, expected > 0 and "
                                  f"<= {MAX_LENGTH_MM:g}; {fix}")
        rows.append(row)
    return np.array(rows, dtype=np.float64)


def spacing_from_text(text: str, sections: int | None, where: str = "--lengths") -> np.ndarray:
    """Parse ``--d`` into one cable distance per section, (k,) mm, each > 0 (the shared distance-list parser).

    With ``sections`` None (not known yet) the values are checked and returned as given.
    """
    import numpy as np

    values = distances_from_text(text, "--d", "cable distance from the backbone", sections, "section", where)
    return np.array(values, dtype=np.float64)
