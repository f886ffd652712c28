"""The names of the mesh formats softdesign writes, and of its per-q files, without readers and writers (no numpy).

The case file's schema (``export.formats``) and ``pose --output`` name the
formats when a command starts; the registry that reads and writes them,
:data:`softdesign.io.formats.FORMATS`, imports numpy.  Its writable formats
are these, in this order (a test checks that the two agree).
"""

from __future__ import annotations

#: Formats a mesh can be written in: ``export.formats`` and ``pose --output``, in the order messages list them.
MESH_FORMATS = ("stl", "ply", "obj", "glb", "vtp")


def q_label(q: float) -> str:
    """``q_0.500``: three decimals, as DESIGN.md names the meshes (the case file refuses two q values with one)."""
    return f"q_{q:.3f}"
