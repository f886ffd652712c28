"""`softdesign init` describes every path and proposes the main vessel (issue 43 item 1).

Stand-ins of the files users brought, each with a small side branch as path 0
(or wherever the extraction puts it): an aortic arch surface in cm (surface
only), a gmsh-like legacy centerline of an aorta with renal and iliac branches
(2-point segments, no radius), a Kawasaki-like aortic root with coronaries
whose surface labels its wall faces, and an ICA with its VMTK centerline.
"""

from __future__ import annotations

import numpy as np
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from tests.helpers.robust_vessels import segment
from tests.helpers.trees import LEAVE_TOL_MM, Limb, Tree, arch_trunk, write_tree

runner = CliRunner()


def _init(tmp_path, *files, units=None):
    case = tmp_path / "case.yaml"
    args = ["init", *(str(f) for f in files), "--output", str(case)] + (["--units", units] if units else [])
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    return case, yaml.safe_load(case.read_text()), case.read_text(), result.output


def _facts_of(text: str) -> list[str]:
    return [line.strip()[2:].strip() for line in text.splitlines() if line.strip().startswith("#   path ")]


def test_ica_with_its_centerline_proposes_the_ica_to_the_mca(tmp_path):
    """VMTK-style centerline, path 0 the ophthalmic artery: the proposal is the ICA into the MCA."""
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, 62.0]), 0.5)
    limbs = (Limb(30.0, (1.0, 0.0, 0.2), 15.0, 0.7), Limb(45.0, (0.0, -1.0, 0.0), 12.0, 0.8),
             Limb(60.0, (-1.0, 0.0, 0.5), 30.0, 1.1), Limb(60.0, (1.0, 0.0, 0.3), 40.0, 1.4))
    tree = Tree(trunk, ((62.0, 2.2),), limbs)
    files = write_tree(tmp_path / "ica", tree, order=[1, 2, 3, 4], edge=0.3)  # ophthalmic, PComm, ACA, MCA
    case, data, text, output = _init(tmp_path, files["surface"], files["centerline"])
    assert data["final"]["path"] == 3  # the MCA's path
    listed = _facts_of(text)
    assert len(listed) == 4 and listed[3].endswith("(the main vessel)")
    assert "the alternatives, widest longest first: path 2, path 1, path 0" in text  # ACA, PComm, ophthalmic
    assert listed[0].startswith("path 0: 45.") and "radius 2.20 mm at the inlet, 0.700 mm at the end" in listed[0]
    leaves = float(listed[0].split("leaves path ")[1].split(" at ")[1].split(" mm")[0])
    np.testing.assert_allclose(leaves, 30.0, rtol=0, atol=LEAVE_TOL_MM)
    assert [f"ends at opening {k}" in line for k, line in enumerate(listed, start=1)] == [True] * 4
    mca = tree.paths()[4][0]
    np.testing.assert_allclose(load_case(case).final.inlet, mca[0], rtol=0, atol=1e-6)
    assert "path: 3, the main vessel" in output
    # validate lists the same paths, and says whether final.path is the main vessel
    checked = runner.invoke(app, ["validate", str(case)])
    assert checked.exit_code == 0, checked.output
    assert all(line in checked.output for line in listed) and "final.path 3 is the main vessel" in checked.output
    case.write_text(text.replace("  path: 3 ", "  path: 0 "))
    other = runner.invoke(app, ["validate", str(case)])
    assert other.exit_code == 0 and "final.path 0 is not the main vessel: path 3 is" in other.output, other.output


def test_gmsh_like_aorta_without_radii_proposes_the_aorto_iliac(tmp_path):
    """2-point segments in a legacy .vtk, no radius (measured on the surface): renal first, the longer iliac
    proposed."""
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, 152.0]), 0.5)
    limbs = (Limb(60.0, (1.0, 0.0, 0.0), 40.0, 3.0), Limb(60.0, (-1.0, 0.0, 0.0), 40.0, 3.0),
             Limb(40.0, (0.0, 1.0, 0.3), 50.0, 3.5), Limb(150.0, (0.5, 0.0, 1.0), 80.0, 5.0),
             Limb(150.0, (-0.5, 0.0, 1.0), 85.0, 5.0))
    tree = Tree(trunk, ((152.0, 10.0),), limbs)
    # renal L, SMA, iliac R (80 mm), renal R, iliac L (85 mm)
    files = write_tree(tmp_path / "aorta", tree, order=[1, 3, 4, 2, 5], centerline="vtk", edge=1.0)
    _, data, text, _ = _init(tmp_path, files["surface"], files["centerline"])
    assert data["final"]["path"] == 4
    listed = _facts_of(text)
    assert len(listed) == 5 and listed[4].endswith("(the main vessel)")
    # the radius was measured on the surface: about the trunk's 10 mm at the inlet, the renal's 3 mm at its end
    inlet = float(listed[0].split("radius ")[1].split(" mm")[0])
    end = float(listed[0].split(" at the inlet, ")[1].split(" mm")[0])
    assert 8.0 < inlet <= 10.0 and 2.0 < end <= 3.0  # a capped end's point lies on its cap: the distance falls


def test_arch_surface_in_cm_proposes_the_descending_aorta(tmp_path):
    """Surface only (the centerlines are extracted), in cm: the supra-aortic branches lose to the descending
    aorta."""
    trunk = arch_trunk()
    top = 40.0 + 25.0 * np.pi
    limbs = tuple(Limb(40.0 + 25.0 * np.pi * f, (0.0, 0.0, 1.0), 40.0, r) for f, r in
                  ((0.35, 4.0), (0.5, 3.0), (0.65, 3.5)))
    tree = Tree(trunk, ((top, 12.0), (trunk.shape[0] * 1.0, 10.0)), limbs)
    files = write_tree(tmp_path / "arch", tree, order=[0], centerline=None, units="cm", edge=1.2)
    case, data, text, _ = _init(tmp_path, files["surface"], units="cm")
    assert data["final"]["centerline"] == "auto"
    listed = _facts_of(text)
    assert len(listed) == 4
    main = data["final"]["path"]
    end = np.array([float(v) for v in listed[main].split("[")[1].split("]")[0].split(",")])
    np.testing.assert_allclose(end, trunk[-1] / 10.0, rtol=0, atol=1.3)  # cm: within the 10 mm radius
    assert "cm (" in listed[0]  # lengths in cm with mm beside
    assert data["units"] == "cm" and load_case(case).final.path == main
    checked = runner.invoke(app, ["validate", str(case)])  # says where the paths come from, without extracting
    assert checked.exit_code == 0 and "final.centerline auto: extracted from final.surface at ingest" in checked.output


def test_labelled_root_with_coronaries_proposes_the_aorta(tmp_path):
    """Kawasaki-like: a wide root, two coronaries leaving it first in the label order, wall faces labelled."""
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, 120.0]), 0.5)
    limbs = (Limb(12.0, (1.0, 0.0, 0.3), 40.0, 2.5), Limb(12.0, (-1.0, 0.0, 0.3), 40.0, 3.0))
    tree = Tree(trunk, ((20.0, 13.0), (120.0, 11.0)), limbs)
    files = write_tree(tmp_path / "kawasaki", tree, order=[0], centerline=None, surface="vtp", edge=1.0,
                       wall_labels=4)
    _, data, text, output = _init(tmp_path, files["surface"])
    listed = _facts_of(text)
    assert len(listed) == 3
    assert data["final"]["path"] == 2 and listed[2].endswith("(the main vessel)")  # the caps' order: coronaries
    assert "face labels are walls, not openings" in output and "warning" not in output
    for line in listed[:2]:  # each coronary leaves the root (or the other coronary, beside it) after its
        # take-off 12 mm up the axis and before the root's 13 mm radius more: the extracted line curves away
        leaves = float(line.split("leaves path ")[1].split(" at ")[1].split(" mm")[0])
        assert 12.0 <= leaves <= 12.0 + 13.0, line
