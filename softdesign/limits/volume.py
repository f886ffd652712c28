"""The bounds of ``export.volume_mesh``: how many tetrahedra, how much memory and time the mesher may take.

fTetWild's memory grows with the tetrahedra it makes.  Measured with
``/usr/bin/time -v`` (peak resident set) on a cylinder of radius 3 mm and
length 20 mm, pytetwild 0.4.2 on one thread: 40,181 tetrahedra 165 MB,
317,878 tetrahedra 484 MB, so about 1.15 kB per tetrahedron over a process
of about 120 MB.  The mesher runs in a child process (beside the build's
own, :mod:`softdesign.limits`), limited to MESHER_MEMORY_BYTES of address
space, so an allocation beyond it fails the stage with a message instead of
taking the machine's memory: room for about a million tetrahedra.  The
count a size asks for is estimated before the mesher starts, as the body's
volume over a regular tetrahedron's (fTetWild made 40,181 where the
estimate said 38,276), and refused above MAX_VOLUME_TETS.  A thin wall or a
fine envelope makes fTetWild refine near the surface far beyond that
estimate (a 0.8 mm wall at a 2 mm size: 5,255 tetrahedra for an estimate
of 170); the memory limit bounds those.
"""

from __future__ import annotations

#: Tetrahedra of one volume mesh, estimated from the body's volume and export.volume_mesh.size_mm.
MAX_VOLUME_TETS = 1_000_000
#: The mesher's child process address space, bytes (1.5 GiB: about 1.15 GB of tetrahedra over its start-up).
MESHER_MEMORY_BYTES = 3 * 2**29
#: The smallest export.volume_mesh.size_mm, mm (the count bound above is what limits a large body).
MIN_TET_SIZE_MM = 0.05
#: q values of export.volume_mesh.q: each mesh takes the mesher seconds to many minutes.
MAX_VOLUME_MESHES = 11
#: The longest export.volume_mesh.timeout_s, s (per mesh).
MAX_MESHER_SECONDS = 3600.0
