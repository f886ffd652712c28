"""Bounds of the ``design`` stage and command (issue 30), free of the case-file models.

The command line checks ``--max-links`` against them without importing :mod:`softdesign.config` (the case
models cost about a third of a second to build, which every command would then pay at start-up).
"""

from __future__ import annotations

#: Most sections a design may search: each k is one joint optimisation (about 0.1 to 0.5 s).
MAX_DESIGN_LINKS = 40
