"""The swept mesh's layers (the l stations of :mod:`softdesign.meshing.sweep_mesh`), planned on the body at q = 0.

Layers evenly ``size_mm`` apart in arc length but at most ``LAYER_ASPECT``
skin edges (the finest grid of the q values meshed, every link joint a
layer), then graded by the skin's stretch near its extremes at every
exported q (:mod:`softdesign.meshing.sweep_grading`), so that the mesh's skin
figures meet the feasibility stage's within issue 32's 1 %; the tetrahedra
they make bounded by ``MAX_VOLUME_TETS`` before the grading and after it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from softdesign.config import Case
from softdesign.config import VolumeMesh as VolumeMeshSpec
from softdesign.errors import ConfigError
from softdesign.fitting.strain import principal_stretches, skin_metric
from softdesign.limits.volume import MAX_VOLUME_TETS
from softdesign.meshing.body import export_l_grid
from softdesign.meshing.sweep_grading import Grading, graded_layers
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.types import FloatArray

#: Largest layer spacing in skin edges: prisms taller than 3 edges split into needles (the demo hollow at 2 mm
#: layers over 0.36 mm skin edges: 26 % of tets under 10 degrees of dihedral, 3.4 degrees the least; at 1 mm:
#: 1.3 %, 6.3 degrees).
LAYER_ASPECT = 3.0
#: The largest relative change of a skin stretch between neighbouring layers (:mod:`softdesign.meshing.
#: sweep_grading`): a skin quad's centre then comes within about half of it of the stretch anywhere in its
#: interval, inside issue 32's 1 % between the mesh's skin and the feasibility stage's.
STRETCH_STEP = 0.01
#: The shortest layer interval, in skin edges around the section (the grading's floor).
MIN_LAYER_EDGES = 0.125
#: Triangles of a section per node about (Euler: 2 per inside node), for the count bound before meshing.
TRIANGLES_PER_NODE = 2.0


def layer_spacing_mm(case: Case, fit: FitResult, size_mm: float) -> float:
    """The layers' spacing: ``size_mm``, at most ``LAYER_ASPECT`` skin edges (2 pi rho / angular_count at the
    median radius at q = 0), so that no prism is much taller than its base is wide."""
    rho = float(np.median(fit.field.evaluate_grid(0.0, np.linspace(0.0, 1.0, 33), [0.0, 0.5 * np.pi, np.pi])))
    return min(size_mm, LAYER_ASPECT * 2.0 * np.pi * rho / case.export.angular_count)


def swept_layers(case: Case, kinematics: KinematicsResult, fit: FitResult,
                 vm: VolumeMeshSpec) -> tuple[FloatArray, FloatArray]:
    """The layers (n,) l: the even ones (:func:`layer_spacing_mm`, the finest grid of the q meshed), graded by
    the skin's stretch near its extremes at every q exported (:mod:`softdesign.meshing.sweep_grading`), the
    count checked; and the even ones (m,) l, a subset (where the reference section is measured)."""
    shape, spacing = kinematics.chain.shape, layer_spacing_mm(case, fit, vm.size_mm)
    grids = [export_l_grid(shape.curve_at(q), fit.field, spacing) for q in sorted({0.0, *vm.q})]
    even = max(grids, key=len)
    _check_count(even, case, fit, vm.size_mm)
    per_layer = _tets_per_layer(even, case, fit, vm.size_mm)
    curve0 = shape.curve_at(0.0)
    grading = Grading(STRETCH_STEP, MIN_LAYER_EDGES * _skin_edge_mm(case, fit),
                      max(len(even), int(MAX_VOLUME_TETS // per_layer) + 1))
    layers = graded_layers(even, curve0.curve.arc_length, _skin_stretches(case, kinematics, fit, vm), grading)
    _check_count(layers, case, fit, vm.size_mm)
    return layers, even


def _skin_edge_mm(case: Case, fit: FitResult) -> float:
    """The skin's edge around the section, 2 pi rho / angular_count at the median radius at q = 0."""
    rho = float(np.median(fit.field.evaluate_grid(0.0, np.linspace(0.0, 1.0, 33), [0.0, 0.5 * np.pi, np.pi])))
    return 2.0 * np.pi * rho / case.export.angular_count


def _skin_stretches(case: Case, kinematics: KinematicsResult, fit: FitResult,
                    vm: VolumeMeshSpec) -> Callable[[FloatArray], FloatArray]:
    """l (m,) -> the skin's principal stretches (m, 2 Q, na), lambda1 and lambda2 at each q the stage exports
    (but 0), at the skin quads' angles: the feasibility stage's metric (:func:`softdesign.fitting.strain.
    skin_metric`), the skin figures the mesh reports and issue 32 compares."""
    shape, field, frames = kinematics.chain.shape, fit.field, case.frames
    na = case.export.angular_count
    angles = 2.0 * np.pi * (np.arange(na) + 0.5) / na
    qs = sorted(set(vm.q) - {0.0})

    def at(l: FloatArray) -> FloatArray:
        rest = skin_metric(shape.curve_at(0.0), field, 0.0, l, angles, frames)
        groups = [g for q in qs for g in principal_stretches(rest, skin_metric(shape.curve_at(q), field, q, l,
                                                                                angles, frames))]
        return np.stack(groups, axis=1) if groups else np.ones((len(l), 2, na))

    return at


def _tets_per_layer(layers: FloatArray, case: Case, fit: FitResult, size_mm: float) -> float:
    """About how many tetrahedra one layer holds (3 per prism, Euler's 2 triangles per section node)."""
    na = case.export.angular_count
    rho = float(np.median(fit.field.evaluate_grid(0.0, layers[:: max(1, len(layers) // 16)], [0.0])))
    inside = np.pi * rho**2 / (0.5 * np.sqrt(3.0) * min(size_mm, 2 * np.pi * rho / na) ** 2)
    return 3.0 * TRIANGLES_PER_NODE * (na + inside)


def _check_count(layers: FloatArray, case: Case, fit: FitResult, size_mm: float) -> None:
    count = (len(layers) - 1) * _tets_per_layer(layers, case, fit, size_mm)
    if count > MAX_VOLUME_TETS:
        raise ConfigError(
            f"export.volume_mesh: the swept mesh would hold about {count:.3g} tetrahedra ({len(layers)} layers of "
            f"{case.export.angular_count} angles at size_mm {size_mm:g}), more than the limit of {MAX_VOLUME_TETS} "
            "(softdesign/limits/volume.py); raise size_mm or lower export.angular_count")
