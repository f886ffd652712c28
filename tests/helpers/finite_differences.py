"""The columns of a derivative checked against central differences: the tangent tests' one loop."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def assert_columns_match_central_differences(matrix: np.ndarray, function: Callable[[np.ndarray], np.ndarray],
                                             x: np.ndarray, h: float, atol: float, every: int) -> None:
    """``matrix[:, k]`` equals ``(function(x + h e_k) - function(x - h e_k)) / 2h`` within ``atol`` for every
    ``every``-th unknown k of ``x`` (V, 3), the unknowns numbered node-major as ``x.ravel()``."""
    for dof in range(0, x.size, every):
        step = np.zeros(x.size)
        step[dof] = h
        difference = (function(x + step.reshape(x.shape)) - function(x - step.reshape(x.shape))) / (2 * h)
        np.testing.assert_allclose(matrix[:, dof], difference, atol=atol)
