"""The errors the command line expects.

Every user-facing failure is a :class:`SoftdesignError`; the CLI maps
:class:`ConfigError` and :class:`InputDataError` to exit code 2 (bad usage or
bad input) and the others to exit code 1 (processing failure).  Anything else
that escapes is a bug and keeps its traceback.

A message says what went wrong, where, what was expected, what was found and
what to do, e.g. ``case.yaml: fit.knot_spacing_mm must be > 0, got -2``.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


class SoftdesignError(Exception):
    """Base class of every error softdesign reports to a user."""

    exit_code = 1


class ConfigError(SoftdesignError):
    """The case file or a command-line option is invalid."""

    exit_code = 2


class InputDataError(SoftdesignError):
    """An input file is missing, unreadable or geometrically unusable."""

    exit_code = 2


class GeometryError(SoftdesignError):
    """A curve, frame or link cannot be computed (e.g. Frenet frame on a straight run)."""


class FitError(SoftdesignError):
    """The surface fit failed or violates a stated bound."""


class FoldError(FitError):
    """The fitted body folds through itself (1 - rho * kappa_n <= 0); the message names the body radius that fits.

    ``stretches`` holds the folding stretches (:class:`softdesign.fitting.local_cap.FoldStretch`) when the fit
    measured them, for the pipeline to name the paths that avoid them.
    """

    stretches: tuple[object, ...] = ()


class InputFitError(FitError, InputDataError):
    """The fit failed because of the inputs (a surface that does not surround the centerline): bad input, exit 2."""

    exit_code = 2


class MeshError(SoftdesignError):
    """A mesh could not be made into a valid solid."""


class SolveError(SoftdesignError):
    """A finite-element solve did not converge (the message names the load step and the residual)."""


@contextmanager
def errors_named_for(source: Path | str) -> Iterator[None]:
    """Prefix a SoftdesignError raised inside the block with ``source`` (e.g. the case file), keeping its type."""
    try:
        yield
    except SoftdesignError as err:
        raise type(err)(f"{source}: {err}") from err
