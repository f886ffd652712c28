"""softdesign/meshing/volume_mesh/sweep_grading.py on known profiles: a narrow peak between two even layers is found and
followed to within the step, a flat stretch adds no layer, and a count over the bound is refused."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.meshing.volume_mesh.sweep_grading import Grading, graded_layers

LENGTH_MM = 60.0
STEP = 0.01


def _arc(l: np.ndarray) -> np.ndarray:
    return LENGTH_MM * np.asarray(l)


def _peak(centre: float, height: float, width_mm: float):
    """lambda1 = 1 + height exp(-(s - centre)^2 / width^2) at 8 angles (scaled by cos), lambda2 = 1 / lambda1:
    (m, 2, 8)."""
    angles = np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False)

    def at(l: np.ndarray) -> np.ndarray:
        bump = height * np.exp(-((_arc(l) - centre) / width_mm) ** 2)
        lam1 = 1.0 + bump[:, None] * (1.0 + np.cos(angles))[None, :] / 2.0
        return np.stack([lam1, 1.0 / lam1], axis=1)

    return at


def test_a_narrow_peak_between_even_layers_is_followed_to_the_step():
    """A peak about 1.2 mm wide on a layer of layers 2 mm apart (the even intervals' middles, the skin quads'
    centres, 1 mm from it, where it has fallen to 1.04): the graded layers' middles reach it within STEP."""
    even = np.linspace(0.0, 1.0, 31)  # 2 mm apart
    centre = float(_arc(even[4]))
    stretches = _peak(centre, 0.6, 0.6)
    l = graded_layers(even, _arc, stretches, Grading(STEP, 0.05, 1000))
    assert np.all(np.isin(even, l)) and np.all(np.diff(l) > 0)
    mids = 0.5 * (l[1:] + l[:-1])
    truth = 1.6
    found = stretches(mids)[:, 0].max()
    assert abs(np.log(found / truth)) <= STEP
    coarse = stretches(0.5 * (even[1:] + even[:-1]))[:, 0].max()
    assert abs(np.log(coarse / truth)) > 5 * STEP  # what the even layers alone give: far off
    # finer near the peak only: the layers added lie within 3 widths of it
    added = np.setdiff1d(l, even)
    assert np.all(np.abs(_arc(added) - centre) < 3 * 0.6 + 2.0)


def test_a_flat_stretch_adds_no_layer_and_the_floor_holds():
    even = np.linspace(0.0, 1.0, 31)
    flat = graded_layers(even, _arc, lambda l: np.full((len(l), 2, 4), 1.2), Grading(STEP, 0.05, 1000))
    np.testing.assert_array_equal(flat, even)
    steep = graded_layers(even, _arc, _peak(31.0, 3.0, 0.05), Grading(STEP, 0.25, 1000))
    assert np.diff(_arc(steep)).min() >= 0.25 - 1e-9


def test_more_layers_than_the_bound_are_refused():
    even = np.linspace(0.0, 1.0, 31)
    with pytest.raises(ConfigError, match="more than 40 layers"):
        graded_layers(even, _arc, _peak(31.0, 0.6, 0.6), Grading(STEP, 0.01, 40))
