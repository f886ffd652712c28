"""The fit stage's morph grid, run in the wall fit's hold-out pool: an error of a q is raised where the morph is
checked, after the fit's own checks, as when the grid had a pool of its own."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from softdesign.errors import GeometryError
from softdesign.fitting.radius_field import fold_margin
from softdesign.pipeline.stages.fit import _morph_job, _raised
from tests.fitting.test_fit_radius_field import _round_field
from tests.helpers.analytic import Arc


def test_a_q_whose_check_raises_returns_its_error_and_the_others_their_reports():
    field = _round_field(lambda l: np.full_like(l, 2.0))

    def curve_at(q: float) -> Arc:
        if q == 0.5:
            raise GeometryError("the frames flip at q = 0.5")
        return Arc(20.0, 0.5)

    task, items = _morph_job(SimpleNamespace(shape=SimpleNamespace(curve_at=curve_at)), field, np.linspace(0, 1, 5))
    results = [task(q) for q in items]
    assert isinstance(results[2], GeometryError)
    assert [_raised(r) for r in results[:2]] == [fold_margin(Arc(20.0, 0.5), field, q) for q in items[:2]]
    with pytest.raises(GeometryError, match="the frames flip at q = 0.5"):
        [_raised(r) for r in results]
