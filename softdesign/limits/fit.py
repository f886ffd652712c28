"""The most wall points the surface's least squares is fitted to (issue 46).

Above :data:`MAX_FIT_POINTS` kept points the spline is fitted to an even
subset of them (:func:`softdesign.fitting.thinning.even_subset`): every knot
cell keeps its share, so the fit sees the wall as densely everywhere.  200,000
points are still ~50 per coefficient on a 240 mm path at 1.5 mm x 24 (the
build's hold-out folds each fit 4/5 of the points measured for RMS, at most
:data:`softdesign.fitting.metrics.DISTANCE_SAMPLE_MAX`, 100,000), and far above
the VMTK aorta's ~4,000 and the demo's ~8,400, which are fitted whole.  The figures
of the fit (true distances, hold-out, all-wall) are still measured on every kept point,
or their seeded samples (:mod:`softdesign.fitting.metrics`).
"""

from __future__ import annotations

MAX_FIT_POINTS = 200_000
