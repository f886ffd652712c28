"""The median of a 1-D array, as ``np.median`` gives it, without importing ``numpy.ma``.

``np.median`` ends with a NaN check whose first use imports ``numpy.ma``
(13-16 ms, a twentieth of ``softdesign validate``'s start-up, which takes
medians of a centerline's radii and steps).  Here the same partition and the
same mean of the middle one or two values give the same float; an array with
a NaN goes to ``np.median`` itself (NaN, as before).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def median(values: npt.ArrayLike) -> float:
    """``float(np.median(values))`` of the values (n,), n >= 1, bit for bit."""
    values = np.asarray(values, float).ravel()
    if len(values) == 0 or not np.isfinite(values).all():  # np.median's own answer (NaN), and its warning
        return float(np.median(values))
    half = len(values) // 2
    kth = [half - 1, half] if len(values) % 2 == 0 else [half]
    return float(np.mean(np.partition(values, kth)[kth]))
