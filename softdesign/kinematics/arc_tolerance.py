"""The stated tolerance of the one-arc-per-link warning (pure Python: the command line shows it in --help).

:mod:`softdesign.kinematics.arc_check` measures the deviation (scipy, through
the blend); this module only holds the figure it is judged against.
"""

from __future__ import annotations

#: The stated tolerance of the warning, mm: about the placement noise of a VMTK centerline on a vessel of a few
#: mm, and a tenth of a typical link's diameter; a link farther than this from every arc needs more sections.
ARC_TOLERANCE_MM = 1.0
