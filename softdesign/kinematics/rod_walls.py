"""The walls of a single-supply device's cross-sections, and the rule between a chamber and the axis thread.

Material walls
    Between two cavities, and between a cavity and the skin: at least the
    material's ``min_wall_mm`` (materials.yaml), a sheet of silicone that a
    pressure difference loads across its thickness and that tears or leaks
    when too thin.
The axis thread (``backbone: inextensible``)
    is not a cavity: it is a solid strand embedded in the silicone, loaded
    along its length, and no pressure acts across the silicone between it
    and a chamber (both sides of that silicone are the body's).  So
    ``min_wall_mm`` is not the rule there.  What is needed is that the
    chamber, with its hoop winding, stays clear of the thread and the
    thread is embedded in silicone all round: the gap from a chamber's (or a
    channel's) surface to the thread's surface is at least
    ``THREAD_GAP_DIAMETERS`` thread diameters: one for the chamber's own hoop
    winding, which is wound on the chamber's core before casting and so lies
    on the cavity's surface (Pagliarani et al., Actuators 2023: thread wound
    round each chamber core before casting in Ecoflex; the Soft Robotics
    Toolkit's fiber-reinforced actuator: Kevlar thread wrapped directly on the
    bladder and then encapsulated by a cast skin), and one of silicone
    between that winding and the axis thread, so that the two threads never
    touch (a stated rule, not a measured limit).
    The last session's rule was a full ``min_wall_mm`` (1 mm in Ecoflex)
    from the chamber to the thread's surface: conservative, and what set the
    demo's P*.

Pure numpy; mm.
"""

from __future__ import annotations

import numpy as np

from softdesign.types import FloatArray

#: The least gap from a chamber's or channel's surface to the axis thread's surface, in thread diameters.
THREAD_GAP_DIAMETERS = 2.0


def thread_gap_mm(thread_diameter_mm: float) -> float:
    """The least gap (mm) between a cavity's surface and the axis thread's surface (see the module notes)."""
    return THREAD_GAP_DIAMETERS * float(thread_diameter_mm)


def cavity_walls(skin_mm: FloatArray, centers: FloatArray, radii: FloatArray, kinds: list[str],
                 extra: tuple[tuple[str, FloatArray], ...] = ()) -> tuple[FloatArray, list[str]]:
    """Each station's thinnest material wall (k,) mm and its kind: between two cavities, to the skin, or one of
    ``extra``'s (kind, (k,) mm).

    Parameters
    ----------
    skin_mm : (k,) mm, the radius walls are measured from
    centers : (k, h, 2) mm;  radii : (k, h) mm, 0 where the cavity does not cross the station
    kinds : (h,) the cavities' names (``chamber``, ``feed``)
    """
    present = radii > 0.0
    reach = np.hypot(centers[..., 0], centers[..., 1])
    skin = np.where(present, skin_mm[:, None] - reach - radii, np.inf)
    gap = np.linalg.norm(centers[:, :, None, :] - centers[:, None, :, :], axis=3) - radii[:, :, None] - radii[:, None]
    both = present[:, :, None] & present[:, None, :] & ~np.eye(radii.shape[1], dtype=bool)[None]
    between = np.where(both, gap, np.inf)
    h, k = radii.shape[1], len(skin_mm)
    every = np.concatenate([skin, between.reshape(k, h * h)] + [v[:, None] for _, v in extra], axis=1)
    best = np.argmin(every, axis=1)
    names = ([f"{kinds[j]}-skin" for j in range(h)] + [f"{kinds[a]}-{kinds[b]}" for a in range(h) for b in range(h)]
             + [kind for kind, _ in extra])
    return every[np.arange(k), best], [names[j] for j in best]


def thread_gaps(centers: FloatArray, radii: FloatArray, thread_diameter_mm: float,
                extra: FloatArray | None = None) -> FloatArray:
    """(k,) mm: each station's smallest gap from a cavity's surface to the axis thread's (inf where none), with
    ``extra`` (k,) mm gaps measured elsewhere (the series channels')."""
    present = radii > 0.0
    reach = np.hypot(centers[..., 0], centers[..., 1])
    gap = np.where(present, reach - radii - 0.5 * thread_diameter_mm, np.inf).min(axis=1, initial=np.inf)
    return gap if extra is None else np.minimum(gap, extra)
