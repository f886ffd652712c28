"""The paths of the network that do not pass through a stretch where the body folds (issue 43, item 2).

A fold's refusal (:mod:`softdesign.fitting.local_cap`) offers a local cap
first; often the user meant another path, one that does not turn into the
take-off.  A path *passes through* a stretch when every point of the selected
path's q = 1 centerline on it, every ``SAMPLE_MM``, lies within
``SHARED_FRACTION`` of the stretch's cap radius of that path's polyline (VMTK's
paths share their common trunk point for point); the others avoid it.
"""

from __future__ import annotations

import numpy as np

from softdesign.errors import FoldError
from softdesign.fitting.local_cap import FoldStretch
from softdesign.fitting.selection import polyline_distances
from softdesign.geometry.network import SelectedPath
from softdesign.types import FramedCurve

#: Spacing of the selected path's points tested on a stretch, mm.
SAMPLE_MM = 0.5
#: A path shares the stretch when it runs within this fraction of the cap radius of every point on it.
SHARED_FRACTION = 0.5
#: The most alternative paths a refusal names (a large tree has hundreds).
MAX_NAMED = 8


def paths_avoiding(stretches: tuple[FoldStretch, ...], curve: FramedCurve,
                   others: tuple[SelectedPath, ...]) -> list[SelectedPath]:
    """The other paths that pass through none of ``stretches`` of the selected path's centerline ``curve``."""
    out = []
    tests = []
    for stretch in stretches:
        count = max(2, int(np.ceil((stretch.cap.to_mm - stretch.cap.from_mm) / SAMPLE_MM)) + 1)
        l = np.clip(np.linspace(stretch.cap.from_mm, stretch.cap.to_mm, count) / curve.length, 0.0, 1.0)
        tests.append((curve.points(l), SHARED_FRACTION * stretch.cap.radius_mm))
    for other in others:
        if not any(np.all(polyline_distances(points, other.points) <= tol) for points, tol in tests):
            out.append(other)
    return out


def with_avoiding_paths(err: FoldError, curve: FramedCurve, others: tuple[SelectedPath, ...]) -> FoldError:
    """The fold's refusal with the paths that avoid its stretches named (the same error when it has no stretches)."""
    stretches = tuple(s for s in err.stretches if isinstance(s, FoldStretch))
    if not stretches:
        return err
    avoiding = sorted(paths_avoiding(stretches, curve, others), key=lambda p: -p.length)
    if not avoiding:
        text = "every other path of the centerline passes through it too"
    else:
        named = ", ".join(f"path {p.index} ({p.length:.1f} mm long)" for p in avoiding[:MAX_NAMED])
        more = f" and {len(avoiding) - MAX_NAMED} more" if len(avoiding) > MAX_NAMED else ""
        text = f"or build a path that does not pass through it (final.path): {named}{more}"
    refusal = FoldError(f"{err}; {text}")
    refusal.stretches = err.stretches
    return refusal
