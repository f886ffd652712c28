"""The load-step control of softdesign.mechanics.newton.solve_pressures: halving a step that fails, doubling after
an easy one, and not trying a length that failed again soon (the module's docstring, "A length that failed ...").

Newton's solve of a step is replaced by a rule with a known answer: a step converges easily when it is at most
``TAKEABLE`` of the load long and fails otherwise, so the lengths the control tries can be checked one by one."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from softdesign.mechanics import newton
from softdesign.mechanics.newton import FAILED_LENGTH_MEMORY, FAILED_LENGTH_SHARE, NewtonSettings, solve_pressures

#: The longest step the made-up path takes, in shares of the load (between the tried lengths 1/32 and 1/16).
TAKEABLE = 0.05


def _tried_lengths(monkeypatch: pytest.MonkeyPatch) -> list[tuple[float, bool]]:
    """Every step length tried on the way to the whole load, and whether it converged."""
    tried: list[tuple[float, bool]] = []
    reached = [0.0]

    def step(problem, u, cavity_pressures, settings, solver, *args, **kwargs):
        length = float(cavity_pressures[0]) - reached[0]
        ok = length <= TAKEABLE + 1e-12
        tried.append((length, ok))
        if ok:
            reached[0] = float(cavity_pressures[0])
            return u, [1.0, 1.0, 1.0, 0.0]  # an easy step (four residuals)
        return None, [1.0, 2.0]  # stopped early, as by an element turned inside out

    monkeypatch.setattr(newton, "_newton_step", step)
    monkeypatch.setattr(newton, "_predicted", lambda problem, u, *args: u)
    problem = SimpleNamespace(mesh=SimpleNamespace(points=np.zeros((1, 3))), fibres=None, fixed=np.zeros(3, bool))
    _, record = solve_pressures(problem, np.array([1.0]), NewtonSettings(load_steps=8, max_cutbacks=6))  # type: ignore[arg-type]
    assert record.load_factors[-1] == pytest.approx(1.0)
    assert record.cutbacks == sum(not ok for _, ok in tried)
    return tried


def test_a_length_that_failed_is_not_tried_again_for_the_next_steps(monkeypatch: pytest.MonkeyPatch) -> None:
    tried = _tried_lengths(monkeypatch)
    # the first 1/8 fails, then 1/16; 1/32 converges twice (a halving does not grow the next), then the next
    # grows to 3/4 of the 1/16 that failed (3/64 < TAKEABLE), and stays there while the failure is remembered
    assert [length for length, _ in tried[:5]] == pytest.approx([1 / 8, 1 / 16, 1 / 32, 1 / 32, 3 / 64])
    converged_since: int | None = None
    for length, ok in tried:
        if not ok:
            failed, converged_since = length, 0
            continue
        if converged_since is not None and converged_since < FAILED_LENGTH_MEMORY:
            assert length <= FAILED_LENGTH_SHARE * failed + 1e-12
        converged_since = None if converged_since is None else converged_since + 1


def test_the_remembered_failure_halves_the_failed_tries_of_plain_doubling(monkeypatch: pytest.MonkeyPatch) -> None:
    remembered = _tried_lengths(monkeypatch)
    monkeypatch.setattr(newton, "FAILED_LENGTH_MEMORY", 0)  # forgotten at once: double after every easy step
    doubling = _tried_lengths(monkeypatch)
    failures = [sum(not ok for _, ok in tried) for tried in (remembered, doubling)]
    # plain doubling ping-pongs: 1/32 converges twice, 1/16 fails, every third try a failure to the end
    assert failures[1] >= 2 * failures[0]
    assert len(remembered) < len(doubling)
