"""The names of the mesh formats softdesign writes, without their readers and writers (no numpy, no vtk).

The case file's schema (``export.formats``) and ``pose --output`` name the
formats when a command starts; the registry that reads and writes them,
:data:`softdesign.io.formats.FORMATS`, imports numpy.  Its writable formats
are these, in this order (a test checks that the two agree).
"""

from __future__ import annotations

#: Formats a mesh can be written in: ``export.formats`` and ``pose --output``, in the order messages list them.
MESH_FORMATS = ("stl", "ply", "obj", "glb", "vtp")
