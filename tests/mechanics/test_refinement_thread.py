"""The reinforced section's curvature under nested refinement (issue 42's known answer "with reinforcement,
curvature changes less than 2 % under one nested refinement"): the studies of tests/helpers/refinement_study.py
with the sample case's hoop thread, their finer levels recorded by ``make study``."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from tests.helpers import refinement_study as study


@pytest.mark.slow
def test_the_threaded_sections_curvature_falls_under_refinement_with_the_solvers_rule() -> None:
    # about 3 s (level 0; the finer ones recorded, see tests/helpers/refinement_study.py).  Recorded (1/mm), the
    # thread at each face's centroid plus 5 % on six points: 6.14415e-4, 5.95379e-4, 5.72892e-4: -3.10 % and -3.78 %
    # per refinement, no asymptotic range (observed order -0.24), so no Richardson value is claimed.  At the centroid
    # alone it was 6.00422e-4, 5.81280e-4, 5.62964e-4 (-3.19 %, -3.15 %); bare, the same section converges from below
    # (+2.9 %, +1.3 %, order 1.12); with the thread it bends less at every level.  Not the rule's doing: the six-point
    # rule alone gives 6.2039e-4 -> 5.9776e-4 (-3.65 %). The octagonal chambers' doing (the next test).  So the first
    # refinement of this default-like mesh (12 nodes round the skin, octagonal chambers, 8.5 mm layers: the simulate
    # command's 3 mm / 8 mm default gives the same polygons) is not within the 2 %.
    kappas, phi_errors = study.checked_levels(study.THREADED)
    changes = kappas[1:] / kappas[:-1] - 1
    assert np.all(changes < 0)  # stiffer at every refinement (bare: softer)
    assert phi_errors.max() < np.deg2rad(0.5)  # the bend stays opposite chamber 0 (the helix's twist is small)


#: The issue's bound: with reinforcement, one nested refinement changes the curvature by less than this.
REFINEMENT_RTOL = 0.02
#: What the round chambers' refinement is held to meanwhile: measured -2.19 % (the issue's 2 % is not met; below).
ROUND_CHAMBER_GUARD = 0.025


@functools.cache
def _round_chamber_change() -> float:
    """Levels 0 and 1 of the recorded study's section with ROUND_CHAMBER_NODES wall nodes round each chamber:
    the curvature's change under one refinement."""
    kappas, phi_errors = study.checked_levels(study.THREADED_ROUND)
    assert phi_errors.max() < np.deg2rad(0.5)
    return float(kappas[1] / kappas[0] - 1)


@pytest.mark.slow
def test_with_round_chambers_one_refinement_moves_the_threaded_curvature_little() -> None:
    # about 8 s of CPU (level 0, 10,800 unknowns; level 1's 74,796, about 75 s, recorded by `make study`).  The same
    # section, thread and load as the recorded study, but 32 wall nodes round each chamber (a polygon 0.6 % short of
    # the circle's area; the octagon's 10 %) in place of 8: measured 7.11500e-4 -> 6.95900e-4 1/mm, -2.19 % (the
    # thread at each face's centroid plus 5 % on six points; at the centroid alone it was -1.78 %, the share's
    # stiffness against the hourglass mode costs 0.4 %).  With the centroid alone the change under one refinement fell
    # with the chamber's polygon (8 nodes -3.19 %, 16 -2.36 %, 32 -1.78 %), grew when the lattice or the layers alone
    # were finer (2 mm across -4.74 %, 4.25 mm layers -4.06 %, both with octagons), and a near-hoop winding of the
    # same stiffness (pitch 0.05 mm) gave -3.04 % on octagons.
    # What the polygon costs is its straight facets (the next test: curved walls), not its area: an octagon of the
    # circle's area (nodes on r sqrt(h / sin h), the pipeline's sections') gave 6.86512e-4 -> 6.64899e-4, -3.15 %,
    # as the inscribed one.  With curved walls the refined level is the same whatever the ring (8, 16, 32 nodes:
    # 7.03747e-4, 7.04127e-4, 7.03763e-4, within 0.06 %) but level 0 is not (7.14264e-4, 7.19066e-4, 7.19495e-4):
    # -1.47 %, -2.08 %, -2.19 % (with the walls' bow spread into the rubber, curved_walls' "Spread", the 32-node
    # ring's 7.19480e-4 -> 7.03755e-4, -2.19 % still).  What is left with 32 nodes is level 0's elements: its fan of
    # triangles into the 4 mm lattice (smallest quality 4 sqrt(3) A / sum l^2 0.09, median 0.15; the octagon's
    # 0.35 and 0.67), which red refinement keeps in shape; with a 2 mm lattice (smallest 0.13, median 0.17) the
    # curved 32-node section moved -1.65 % (octagons -0.93 %).
    assert -ROUND_CHAMBER_GUARD < _round_chamber_change() < 0.0


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 42's 2 % under one refinement is not met with 32 straight wall nodes "
                                       "round each chamber: -2.19 % (curved walls give -2.19 % on this mesh too: "
                                       "its level 0's elements, see the test above; the octagons' curved walls "
                                       "meet it, the next test)")
def test_with_round_chambers_one_refinement_moves_the_threaded_curvature_by_less_than_two_percent() -> None:
    # the same level 0 solve as the test above, and the same record
    assert abs(_round_chamber_change()) < REFINEMENT_RTOL


@pytest.mark.slow
def test_with_curved_chamber_walls_one_refinement_moves_the_threaded_curvature_by_less_than_two_percent() -> None:
    # about 1 s of CPU (level 0; levels 1 and 2, 13 s and 11 minutes of CPU, recorded by `make study`).  Issue 42's
    # known answer "with reinforcement, curvature changes less than 2 % under one nested refinement" on the
    # recorded study's default-like mesh (octagons, 4 mm across, 8.5 mm layers, the sample case's thread), its
    # chambers' walls on their circles (softdesign.mechanics.curved_walls) and refined through the curved elements'
    # maps, so that every level has the same round chambers, the walls' bow spread into the rubber beside them
    # (curved_walls, "Spread").  Measured: 7.14264e-4, 7.03715e-4, 7.02609e-4 1/mm: -1.48 % and -0.16 %, observed
    # order 3.25 (Richardson 7.0248e-4; without the spread 7.14264e-4, 7.03747e-4, 7.02614e-4, -1.47 % and -0.16 %:
    # on this mesh no element beside a wall is thin enough for its bow to matter).  With straight octagons it gave
    # -3.10 % and -3.78 % with no asymptotic range (the first test).  On the pipeline's own section at the simulate
    # command's mesh (tests/mechanics/test_section_symmetry.py's, 5 kPa, its thread), one refinement moved the
    # curvature by -3.83 % with its straight octagons of the circles' area and -0.44 % with curved walls (the model's
    # default: 6.40708e-4 -> 6.37901e-4 1/mm; -0.45 % before the spread).
    kappas, phi_errors = study.checked_levels(study.THREADED_CURVED)
    changes = kappas[1:] / kappas[:-1] - 1
    assert np.all(np.abs(changes) < REFINEMENT_RTOL)
    assert phi_errors.max() < np.deg2rad(0.5)
