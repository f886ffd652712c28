"""The bounds of ``softdesign simulate``: pressures, load steps, iterations, mesh size, time and memory of a solve.

A section's solve factors a sparse matrix (SuperLU, in METIS's nested-dissection
order) once per Newton iteration; its fill, and so its time and memory, grows
faster than the node count (3D).  Measured (CPU time, quadratic tetrahedra, on
the 2-core machine): the sample case's base section, 6,428 nodes, 1.4 s per
factorization and 14.7 M entries in the factors (about 0.2 GB); before the
METIS order, SuperLU's own orders took 0.6 s at 3,270 nodes, 7.0 s at 6,428,
9.7 s at 7,392 (43 M entries) and 19.6 s at 10,840.
MAX_SECTION_NODES (nodes of the quadratic mesh: corners and edge midpoints)
keeps one solve within SIMULATE_MEMORY_BYTES (the child's address space) and
minutes, and is checked on the mesh before the solve starts.
"""

from __future__ import annotations

#: Largest chamber pressure, kPa (10 bar: far beyond what a silicone chamber holds).
MAX_PRESSURE_KPA = 1000.0
#: Load steps of a solve (each one a Newton solve), and Newton iterations per step.
MAX_LOAD_STEPS = 64
MAX_NEWTON_ITERATIONS = 50
#: Forward solves of one inverse search.
MAX_INVERSE_SOLVES = 40
#: q values of a build's simulate block (each one inverse per section).
MAX_SIMULATE_Q = 11
#: Nodes of one section's quadratic mesh.
MAX_SECTION_NODES = 12_000
#: The smallest element and layer size, mm.
MIN_SIZE_MM = 0.2
#: Nodes on the outer circle of a section.
MIN_ANGULAR_COUNT, MAX_ANGULAR_COUNT = 8, 256
#: The child's address space, bytes (2 GiB), and the longest time a solve may take, s.
SIMULATE_MEMORY_BYTES = 2**31
MAX_SIMULATE_SECONDS = 3600.0
#: Nodes of the whole device's quadratic mesh (``simulate --all``): its factorization's fill grows about with the
#: device's length times its cross-section's unknowns squared; measured on the demo's device at the default mesh
#: (8,546 nodes, 25k unknowns): 5 s per factorization on the 2-core machine under load.
MAX_DEVICE_NODES = 40_000
#: The whole device's child's address space, bytes (6 GiB): its element matrices alone are (E * 4, 30, 30) floats,
#: 141 MiB a copy on the demo's device at the default mesh, over the section's 2 GiB (measured: it ran out there).
DEVICE_MEMORY_BYTES = 6 * 2**30
