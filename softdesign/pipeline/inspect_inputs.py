"""What a user's own vessel files hold, for ``softdesign init``: paths, their sizes, openings, units, an inlet.

With a centerline file, its paths are read as a build reads them (each
oriented by the build's own rule, so the proposed inlet is where the build
would start).  With a surface alone, the centerlines are extracted as
``final.centerline: auto`` would extract them, so what is listed is what the
build will get.  Every path is described (length, radius at the inlet and
at the end, where it leaves the others, the opening it ends at) and the main
vessel is proposed by :func:`softdesign.geometry.path_survey.main_path`'s rule
(the path of largest lumen volume); a centerline without radii is measured
against the surface for it.  The unit is guessed from the sizes
(:func:`softdesign.geometry.units_guess.guess_units`) unless the user gives
it; an ambiguous guess is refused with the evidence.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softdesign.errors import ConfigError
from softdesign.geometry.path_survey import PathFacts, main_path, survey_paths
from softdesign.geometry.units_guess import UnitGuess, guess_units
from softdesign.types import UNIT_SCALE_TO_MM, FloatArray, Points


@dataclass(frozen=True)
class PathSummary:
    """One path of the vessel, in the files' own unit.

    Attributes
    ----------
    index : the case's ``final.path`` value that selects it
    points : (n, 3) float, inlet first
    radius : (n,) float or None -- inscribed radius along it
    """

    index: int
    points: Points
    radius: FloatArray | None

    @property
    def length(self) -> float:
        """Polyline length, in the files' unit."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    @property
    def median_radius(self) -> float | None:
        """Median inscribed radius, or None without radii."""
        return None if self.radius is None else float(np.median(self.radius))


@dataclass(frozen=True)
class Inspection:
    """What ``init`` found in the files.

    Attributes
    ----------
    surface, centerline : the files (centerline None: it will be extracted, ``centerline: auto``)
    paths : every path, inlet first, in the files' unit
    openings : (k, 3) float -- the path ends: the inlet first, then each path's far end
    units : the files' unit, given or guessed
    guess : the evidence for it (None when the user gave it)
    facts : what each path is, in the files' unit, in the order of ``paths``
    main : the ``path`` value proposed: the main vessel
    notes : what extracting the centerlines said (the wall labels, warnings), as the build's ingest says it
    """

    surface: Path
    centerline: Path | None
    paths: tuple[PathSummary, ...]
    openings: FloatArray
    units: str
    guess: UnitGuess | None
    facts: tuple[PathFacts, ...] = ()
    main: int = 0
    notes: tuple[str, ...] = ()

    @property
    def main_path(self) -> PathSummary:
        """The path proposed (the main vessel)."""
        return next(p for p in self.paths if p.index == self.main)

    @property
    def inlet(self) -> FloatArray:
        """The proposed inlet: where the main vessel starts, (3,) in the files' unit."""
        return self.main_path.points[0]


def inspect_inputs(surface: Path, centerline: Path | None, units: str | None) -> Inspection:
    """Read the files and summarise them (see the module notes).

    Raises
    ------
    ConfigError
        ``units`` not given and the sizes fit more than one unit, or none.
    InputDataError
        A file that cannot be read as a surface or a centerline.
    """
    paths, notes = (_centerline_paths(centerline), ()) if centerline is not None else _extracted_paths(surface)
    guess = None
    if units is None:
        radii = [p.median_radius for p in paths]
        known = [r for r in radii if r is not None]
        guess = guess_units([p.length for p in paths], known if len(known) == len(radii) else None)
        if guess.units is None:
            raise ConfigError(_ambiguous(guess))
        units = guess.units
    openings = np.array([paths[0].points[0]] + [p.points[-1] for p in paths], float)
    facts = survey_paths(_with_radii(paths, surface))
    return Inspection(surface, centerline, tuple(paths), openings, units, guess, tuple(facts), main_path(facts),
                      notes)


def _with_radii(paths: list[PathSummary], surface: Path) -> list[tuple[int, Points, FloatArray | None]]:
    """The paths for the survey; a path without radii gets its distance to ``surface`` (read in its own unit)."""
    if all(p.radius is not None for p in paths):
        return [(p.index, p.points, p.radius) for p in paths]
    from softdesign.io.surface import read_surface
    from softdesign.meshing.compare import squared_distances

    vertices, faces = read_surface(surface)  # the files' own numbers, as the centerline's
    return [(p.index, p.points, p.radius if p.radius is not None
             else np.sqrt(squared_distances(p.points, vertices, faces))) for p in paths]


def inspection_path_lines(inspection: Inspection) -> list[str]:
    """Every path in words, the main vessel marked (:func:`softdesign.pipeline.path_text.path_lines`)."""
    from softdesign.pipeline.path_text import path_lines

    return path_lines(inspection.facts, inspection.units, UNIT_SCALE_TO_MM[inspection.units], inspection.main)


def _centerline_paths(centerline: Path) -> list[PathSummary]:
    from softdesign.geometry.network import all_paths
    from softdesign.io.centerline import read_centerline_network

    network = read_centerline_network(centerline)  # the file's own numbers: the unit is not known yet
    return [PathSummary(p.index, p.points, p.radius) for p in all_paths(network)]


def _extracted_paths(surface: Path) -> tuple[list[PathSummary], tuple[str, ...]]:
    from softdesign.centerline.extract import CenterlineOptions, extract_centerlines
    from softdesign.io.centerline_vtp import read_face_regions
    from softdesign.io.surface import read_surface

    vertices, faces = read_surface(surface)
    options = CenterlineOptions(regions=read_face_regions(surface))
    result = extract_centerlines(vertices, faces, options, str(surface))
    paths = [PathSummary(k, p, r) for k, (p, r) in enumerate(zip(result.paths, result.radii, strict=True))]
    return paths, result.notes


def _ambiguous(guess: UnitGuess) -> str:
    if guess.plausible:
        why = f"the sizes are a human vessel's in {' and in '.join(guess.plausible)}"
    else:
        why = "the sizes are no human vessel's in any of " + ", ".join(UNIT_SCALE_TO_MM)
    return (
        f"cannot tell the files' unit: {why} ({'; '.join(guess.evidence)}); "
        "give it: softdesign init ... --units mm (or cm, m)"
    )
