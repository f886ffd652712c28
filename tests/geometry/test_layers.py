"""Layers import downward only: geometry is the numeric core and never reaches kinematics (or anything above it)."""

from __future__ import annotations

import json
import pkgutil
import subprocess
import sys

import pytest

import softdesign.geometry

GEOMETRY_MODULES = sorted(f"softdesign.geometry.{m.name}" for m in pkgutil.iter_modules(softdesign.geometry.__path__))
#: What geometry may import from the package besides itself: the error classes and the array conventions.
ALLOWED = ("softdesign", "softdesign.errors", "softdesign.types")


def _softdesign_modules_loaded_by(module: str) -> list[str]:
    """Every softdesign module in sys.modules after importing ``module`` in a fresh interpreter."""
    code = (
        f"import json, sys; import {module}; "
        "print(json.dumps(sorted(m for m in sys.modules if m == 'softdesign' or m.startswith('softdesign.'))))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def test_every_geometry_module_is_found():
    assert "softdesign.geometry.se3" in GEOMETRY_MODULES and len(GEOMETRY_MODULES) >= 6


@pytest.mark.parametrize("module", GEOMETRY_MODULES)
def test_no_geometry_module_imports_kinematics_or_a_higher_layer(module):
    loaded = _softdesign_modules_loaded_by(module)
    assert [m for m in loaded if m.startswith("softdesign.kinematics")] == []
    outside = [m for m in loaded if m not in ALLOWED and not m.startswith("softdesign.geometry")]
    assert outside == [], f"{module} imports {outside}"
