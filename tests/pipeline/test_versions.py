"""softdesign.pipeline.versions: the one place that says which software a build ran with."""

from __future__ import annotations

import platform
from importlib import metadata

from softdesign import __version__
from softdesign.pipeline.versions import NOT_INSTALLED, software_versions

#: The keys every manifest records, in order.
RECORDED = ["softdesign", "python", "numpy", "scipy", "vtk", "trimesh", "manifold3d", "pydantic"]


def test_versions_are_the_installed_ones_in_a_fixed_order():
    versions = software_versions()
    assert list(versions) == RECORDED
    assert versions["softdesign"] == __version__
    assert versions["python"] == platform.python_version()
    for name in RECORDED[2:]:
        assert versions[name] == metadata.version(name), name


def test_extra_distributions_follow_and_a_missing_one_says_so():
    versions = software_versions(("matplotlib", "no-such-distribution-softdesign"))
    assert list(versions) == RECORDED + ["matplotlib", "no-such-distribution-softdesign"]
    assert versions["matplotlib"] == metadata.version("matplotlib")
    assert versions["no-such-distribution-softdesign"] == NOT_INSTALLED
