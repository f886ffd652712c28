"""Compare a build folder with a reference build folder, figure by figure (``softdesign check``).

What is compared, and against which tolerance (:class:`CheckOptions`):

- every mesh file under ``meshes/`` (any format of :mod:`softdesign.io.formats`) present on either
  side, by name, through :func:`softdesign.meshing.compare.compare_meshes`:
  symmetric surface distance max and RMS (``distance_mm``), relative change of
  volume and area (``rtol``), watertightness (must equal the reference's).
  A mesh on one side only, or one that cannot be read, fails;
- ``kinematics.json`` per q and link: translation difference of the link
  transform (mm, ``distance_mm``), angle of the rotation between the two
  transforms (rad, ``rotation_rad``), link length and POE theta1 (mm,
  ``distance_mm``), POE theta2 (rad, ``rotation_rad``); the same for each
  pose's ``base_to_tip`` and ``base_to_world`` (where present); the frame
  convention must match.  A pose is matched by its q, one value or one per
  link as the kinematics stage writes it;
- the fit metrics ``manifest.json: metrics.fit.*_mm`` (residuals: the smaller of ``distance_mm`` and
  ``rtol`` of the reference plus a floor, :func:`~softdesign.regression.figures.residual_tolerance`);
- the other stages' figures in the manifests (:mod:`~softdesign.regression.sections`: links, blend, the
  kinematics' arc check, the design's chain, mould, volume mesh; feasibility by its own module), each within
  the named tolerance of its row.

When the two manifests name different cases, or the same case built from
input files of other content (sha256), the report carries a warning: the
figures then measure two vessels, not a change.  It is not a failure.

Any change beyond tolerance fails, an improvement included: a reference is
updated on purpose, never drifted past.

The rotation tolerance is a fixed angle rather than ``distance_mm / link
length``: a rotation error in one link swings every link after it, so a short
link does not earn a looser angle; 1e-4 rad moves the tip of a 100 mm
actuator by 0.01 mm, the default ``distance_mm``.

A reference may hold decimated meshes.  The step that makes it then writes
``REF_DIR/golden.json``::

    {"meshes": {"meshes/q_0.000.stl": {"distance_max_mm": 0.004,
                                       "volume_rel_change": -1e-4,
                                       "area_rel_change": -3e-4}}, ...}

with the figures of the stored mesh against the full-resolution one
(:func:`decimation_entry`), and check adds them to that mesh's tolerances:
``distance_mm + distance_max_mm`` for max and RMS distance (a point within
``distance_mm`` of the full surface is within ``distance_mm + distance_max_mm``
of the stored one: the triangle inequality), ``rtol + |volume_rel_change|`` and
``rtol + |area_rel_change|`` (to first order).  Other keys (versions, case
hash) are ignored here.  Watertightness is compared with the stored mesh, so
the golden step must decimate without opening it.

Layout: :mod:`~softdesign.regression.figures` (Figure, CheckOptions,
CheckReport and the helpers every comparison shares),
:mod:`~softdesign.regression.meshes` (meshes and golden.json),
:mod:`~softdesign.regression.kinematics` (kinematics.json) and
:mod:`~softdesign.regression.check` (:func:`check_build`, the fit metrics of
manifest.json).  The names below are this package's public API.
"""

from softdesign.regression.check import FIT_KEYS, MANIFEST, case_warnings, check_build, compare_fit
from softdesign.regression.figures import CheckOptions, CheckReport, Figure, Value, scalar_figure
from softdesign.regression.kinematics import (
    KINEMATICS,
    POSE_TRANSFORMS,
    Q_DECIMALS,
    compare_kinematics,
    pose_difference,
)
from softdesign.regression.meshes import (
    GOLDEN,
    MESH_SUFFIXES,
    DecimationError,
    compare_mesh_folders,
    decimation_entry,
    mesh_figures,
    mesh_names,
    read_golden,
)

__all__ = [
    "FIT_KEYS",
    "GOLDEN",
    "KINEMATICS",
    "MANIFEST",
    "MESH_SUFFIXES",
    "POSE_TRANSFORMS",
    "Q_DECIMALS",
    "CheckOptions",
    "CheckReport",
    "DecimationError",
    "Figure",
    "Value",
    "case_warnings",
    "check_build",
    "compare_fit",
    "compare_kinematics",
    "compare_mesh_folders",
    "decimation_entry",
    "mesh_figures",
    "mesh_names",
    "pose_difference",
    "read_golden",
    "scalar_figure",
]
