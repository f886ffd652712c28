"""The case file: YAML -> validated models, defaults filled in, paths resolved.

A case file is YAML validated by pydantic models that forbid unknown keys.
Errors are reported with the file, the line, the dotted field, what was
expected and what was found; an unknown key gets the nearest valid key as a
suggestion.  Relative paths are relative to the case file.  ``units`` names
the unit of the *input files* (and of ``final.inlet``); everything inside
softdesign is millimetres, the conversion happens at ingest.

Each block of the case has its module (``shapes``: final, initial, intermediate; ``resample``; ``links``;
``fit``; ``export`` with its mould and volume mesh; ``material``; ``actuation``; ``design``; ``simulate``),
``case`` the whole file and :func:`load_case`, ``messages`` the error messages.  The names below are the
package's public ones.
"""

from __future__ import annotations

from softdesign.config.case import Case, load_case
from softdesign.config.export import Export, Mould, VolumeMesh
from softdesign.config.fit import MAX_END_MARGIN_MM, Fit
from softdesign.config.links import Links
from softdesign.config.material import Material
from softdesign.config.resample import Resample
from softdesign.config.shapes import FinalShape, InitialShape, IntermediateShape

__all__ = ["MAX_END_MARGIN_MM", "Case", "Export", "FinalShape", "Fit", "InitialShape", "IntermediateShape", "Links",
           "Material", "Mould", "Resample", "VolumeMesh", "load_case"]
