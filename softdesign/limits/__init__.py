"""Every size a case file can ask for, bounded so that a build stays within MEMORY_BUDGET_BYTES.

The machine a build runs on is shared (``make -j`` runs several at once), so
a build may use at most :data:`MEMORY_BUDGET_BYTES` = 2 GiB.  The bounds
below are derived from what each size costs, measured with
``/usr/bin/time -v softdesign build`` on configs/demo.yaml (a 104.5 mm
artery, 8455 surface vertices):

* the process itself (Python, numpy, scipy, vtk, trimesh, manifold3d and the
  input surface) peaks at about 400 MB (386 MB for the demo's whole build);
* one export mesh peaks at about 850 bytes per vertex while it is built and
  checked (54k vertices: 386 MB, 1.07 M vertices: 1217 MB; slope 0.82 kB);
* a kept mesh (float64 vertices, int64 faces, region labels, the per-region
  pieces) holds at most 200 bytes per vertex until the stage writes them all;
* a centerline sample (the quintic spline, frames, blend and kinematics
  arrays) costs about 3 kB (10448 samples: +31 MB over 210 samples);
* the sparse fit's factorisation holds at most (coefficients) x (band
  2 x 4 x angular_intervals) float64, 330 MB at the bounds below.

So the budget splits as 400 MB (process) + 850 MB (one mesh of
MAX_MESH_VERTICES) + 400 MB (kept meshes, MAX_EXPORT_VERTICES) + 150 MB
(MAX_CURVE_SAMPLES) + 330 MB (fit) = 2130 MB < 2147 MB; the fit's and the
mesh's peaks do not even coincide.  Counts that cost time rather than memory
(folds, q values) are bounded so a build ends in minutes.

Checked at the bounds under ``RLIMIT_AS`` = 2 GiB (configs/demo.yaml): one
mesh of 992,258 vertices (export.spacing_mm 0.108, angular_count 1024) built
in 17 s with a 1.11 GB peak; two meshes of 1.9 M vertices together in 14 s
with 1.23 GB; a fit of 19,968 coefficients (knot_spacing_mm 1.4,
angular_intervals 256) in 58 s with 634 MB.

The counts that do not depend on the vessel are checked by the schema
(``softdesign validate``); those that follow from a spacing and the vessel's
length are checked by :mod:`softdesign.pipeline.bounds` once ingest has
measured the vessel, before any other stage starts.
"""

from __future__ import annotations

#: What one build may use, bytes (2 GiB).
MEMORY_BUDGET_BYTES = 2 * 1024**3
#: The budget in words, for messages.
MEMORY_BUDGET_TEXT = "2 GiB"

#: Samples along a centerline (resample.count, or length / resample.spacing_mm): 3 kB each, 150 MB.
MAX_CURVE_SAMPLES = 50_000
#: Vertices of one export mesh (rings x angular_count, twice with a wall): 850 B each while built, 850 MB.
MAX_MESH_VERTICES = 1_000_000
#: Vertices of all export meshes together, kept until the stage writes them: 200 B each, 400 MB.
MAX_EXPORT_VERTICES = 2_000_000
#: Export q values (export.q entries or export.frames): 1001 keeps every mesh name unique with three
#: decimals (frames 1001 step by exactly 0.001).
MAX_EXPORT_Q = 1001
#: Vertices around one export ring (export.angular_count): 1024 is a 0.006% area error on a round section.
MAX_ANGULAR_COUNT = 1024
#: Links (links.count, breaks, or length / links.length_mm): a link is a segment of a catheter-sized actuator.
MAX_LINKS = 100
#: Angular knot intervals of the fit (fit.angular_intervals).
MAX_ANGULAR_INTERVALS = 256
#: Coefficients of the fit, (length / fit.knot_spacing_mm + 3) x angular_intervals; the default aorta fit
#: has about 4.8 thousand.  With the band of 8 x 256 float64 per row this is 330 MB.
MAX_FIT_COEFFICIENTS = 20_000
#: Hold-out folds of the fit (fit.holdout_folds): each refits the surface once.
MAX_HOLDOUT_FOLDS = 20
