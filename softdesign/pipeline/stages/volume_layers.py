"""The swept mesh's layers (the l stations of :mod:`softdesign.meshing.volume_mesh.sweep_mesh`), planned on the body at
q = 0.

Layers evenly ``size_mm`` apart in arc length (the finest grid of the q
values meshed, every link joint a layer), then graded by the skin's stretch near its extremes at every
exported q (:mod:`softdesign.meshing.volume_mesh.sweep_grading`), so that the mesh's skin
figures meet the feasibility stage's within issue 32's 1 %; the tetrahedra
they make bounded by ``MAX_VOLUME_TETS`` before the grading and after it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import numpy as np

from softdesign.config import Case
from softdesign.config import VolumeMesh as VolumeMeshSpec
from softdesign.errors import ConfigError
from softdesign.fitting.strain import principal_stretches, skin_metric
from softdesign.limits.volume import MAX_VOLUME_TETS
from softdesign.meshing.body.sections import export_l_grid
from softdesign.meshing.volume_mesh.sweep_grading import Grading, graded_layers
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.types import FloatArray

T = TypeVar("T")

#: The layers follow ``size_mm``, not the skin's edge (2 pi rho / angular_count): a cap of 3 skin edges made
#: the actuator's 101 layers (543,216 tets, 8-9 s CPU) at every size_mm from 2 to 8.  Prisms taller than their
#: skin edge cost needles at the skin, reported as the mesh's least dihedral angle and its worst element (the
#: demo hollow: 5.8 degrees the least at 3 skin edges, 3.1 at 2 mm layers): a smaller size_mm buys quality
#: with elements.  Layers too far apart for a bend can invert a tetrahedron or miss the volume (the aorta
#: chambered at 4 mm layers: one inverted at q = 1; the demo solid at 4 mm: -0.50 % at q = 1), so the stage
#: halves the spacing (:func:`sound_layers`) down to ``LAYER_ASPECT`` skin edges, the spacing meshed before.
LAYER_ASPECT = 3.0
#: The largest relative change of a skin stretch between neighbouring layers (:mod:`softdesign.meshing.
#: sweep_grading`): a skin quad's centre then comes within about half of it of the stretch anywhere in its
#: interval, inside issue 32's 1 % between the mesh's skin and the feasibility stage's.
STRETCH_STEP = 0.01
#: The shortest layer interval, in skin edges around the section (the grading's floor).
MIN_LAYER_EDGES = 0.125
#: Triangles of a section per node about (Euler: 2 per inside node), for the count bound before meshing.
TRIANGLES_PER_NODE = 2.0


def sound_layers(size_mm: float, floor_mm: float, plan: Callable[[float], T],
                 sound: Callable[[T], bool]) -> T:
    """``plan(spacing)`` at ``size_mm``, the spacing halved while ``sound`` refuses the plan (an inverted
    tetrahedron, a volume off at an exported q) and it exceeds ``floor_mm`` (then the floor's plan, checked by
    the stage as every plan is)."""
    spacing = float(size_mm)
    while True:
        planned = plan(spacing)
        if spacing <= floor_mm or sound(planned):
            return planned
        spacing = max(floor_mm, 0.5 * spacing)


def floor_spacing_mm(case: Case, fit: FitResult) -> float:
    """The finest even spacing :func:`sound_layers` falls back to: ``LAYER_ASPECT`` skin edges."""
    return LAYER_ASPECT * _skin_edge_mm(case, fit)


def swept_layers(case: Case, kinematics: KinematicsResult, fit: FitResult, vm: VolumeMeshSpec,
                 spacing: float) -> tuple[FloatArray, FloatArray]:
    """The layers (n,) l: the even ones (``spacing`` mm apart, the finest grid of the q meshed), graded by
    the skin's stretch near its extremes at every q exported (:mod:`softdesign.meshing.volume_mesh.sweep_grading`), the
    count checked; and the even ones (m,) l, a subset (where the reference section is measured)."""
    shape = kinematics.chain.shape
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
