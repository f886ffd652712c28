"""The versions of the software that shape a build's numbers, computed in this one place.

The manifest records them (``"software"``), the report shows them beside the
versions that drew the page, and ``make golden`` stores them with the
references, so a difference between two builds can be traced to a release.
"""

from __future__ import annotations

import platform
from importlib import metadata

from softdesign import __version__

#: Distributions whose versions every build records, in this order, after softdesign and Python.
PACKAGES = ("numpy", "scipy", "vtk", "trimesh", "manifold3d", "pydantic")
#: What stands for the version of a distribution that is not installed.
NOT_INSTALLED = "not installed"


def software_versions(extra: tuple[str, ...] = ()) -> dict[str, str]:
    """Versions of softdesign, Python, :data:`PACKAGES` and then ``extra`` distributions, in that order.

    Parameters
    ----------
    extra : more distribution names (as pip knows them), e.g. ``("matplotlib",)``

    Returns
    -------
    ``{"softdesign": "0.1.0", "python": "3.11.7", "numpy": "2.4.6", ...}``;
    a distribution that is not installed reads ``"not installed"``.
    """
    versions = {"softdesign": __version__, "python": platform.python_version()}
    for name in PACKAGES + tuple(extra):
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = NOT_INSTALLED
    return versions
