"""Feasibility on worker processes (issue 19): the same figures whatever --jobs is, and the kept rest state's
metric is the one computed afresh."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softdesign.config import load_case
from softdesign.meshing.body.skin_stretch import make_grid
from softdesign.meshing.body.wall import FD_STEP_MM
from softdesign.pipeline.api import build_through
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.parallel import jobs_for_build
from softdesign.pipeline.stage_order import STAGES
from softdesign.pipeline.stages.feasibility import _Body, run_feasibility
from tests.helpers.cases import write_case
from tests.helpers.paths import REPO

#: A whole build of the demo: `make test-fast` leaves it out.
pytestmark = pytest.mark.slow

DEMO = REPO / "data" / "demo"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The demo, hollow and ported (so the chamber and the wall are measured too), built once; its results."""
    folder = tmp_path_factory.mktemp("feasibility-jobs")
    case_file = write_case(
        folder, "demo-hollow",
        final={"centerline": str(DEMO / "centerline.vtp"), "surface": str(DEMO / "surface.stl"), "path": 0},
        export={"q": [0.0, 0.25, 0.5, 0.75, 1.0], "wall_mm": 1.0, "port_mm": 1.5},
    )
    out = folder / "build"
    build_through(case_file, out, jobs=1)
    results: dict = {}
    for stage in STAGES:
        if stage.name in ("blend", "links", "kinematics", "fit"):
            results[stage.name] = stage.load(out, results)
    return load_case(case_file), out, results  # loaded as a later run would: the same inputs for every jobs


def test_feasibility_is_the_same_bytes_with_one_and_two_jobs(built):
    case, _, results = built
    texts = {}
    for jobs in (1, 2):
        with jobs_for_build(jobs):
            summary = run_feasibility(case, results["kinematics"], results["fit"]).summary
        texts[jobs] = json.dumps(summary, sort_keys=True)
    assert texts[1] == texts[2]


def test_the_kept_rest_metric_is_the_metric_computed_afresh(built):
    case, _, results = built
    body = _Body(results["kinematics"].chain.shape, results["fit"].field, body_spec(case), case.frames)
    for offset, span in ((0.0, (0.0, 1.0)), (-1.0, body.span(0.0, 1.0 + 2 * FD_STEP_MM))):
        grid = make_grid(body.length, body.field.breaks, 0.5, 96, span)
        rest = body.rest(offset)
        first, again = rest(grid.l, grid.a), rest(grid.l, grid.a)
        assert again is first and not first.flags.writeable  # kept, and nobody may change it
        assert np.array_equal(first, body.surface(0.0, offset)(grid.l, grid.a))
