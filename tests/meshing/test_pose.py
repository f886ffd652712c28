"""`softdesign pose`: the body with one q per link (the seed's S_robot).

Known answers first (rings on rays, annuli between concentric and crossing rings, a straight
link followed by an arc, solid and hollow), then the sample case end to end: equal q reproduces
the build's meshes (hollow ones too), mixed q places every link on the previous link's end frame
and closes each step.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
import typer
import yaml
from typer.testing import CliRunner

from softdesign.cli import build
from softdesign.cli.pose import pose
from softdesign.errors import MeshError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import smooth_curve_from_samples
from softdesign.geometry.initial import straight_initial_shape
from softdesign.kinematics.links import LinkChain
from softdesign.meshing.body.pose import PoseSpec, check_distinct_when_written, pose_body
from softdesign.meshing.body.pose_stitch import JOINT_MERGE_TOL_MM, radii_on_rays, stitch_joint
from softdesign.meshing.checks import inspect_mesh
from softdesign.meshing.compare import compare_meshes
from softdesign.meshing.tessellate import Region
from tests.helpers.paths import REPO

app = typer.Typer(add_completion=False)
app.command()(pose)
app.command()(build)
runner = CliRunner()
DEMO = REPO / "configs" / "demo.yaml"

#: Round-off of a few products of rigid transforms on coordinates of ~100 mm.
PLACEMENT_TOL_MM = 1e-9
#: Areas and radii built from O(3 mm) values in a handful of operations.
ROUND_TOL = 1e-12
#: The arc is a quintic spline through samples every 0.5 mm: it follows the circle to ~1e-9 mm (measured).
ARC_TOL_MM = 1e-8
#: Equal q: the same rings as the export (~1e-13 mm apart); the STL files hold float32 of those.
EQUAL_Q_TOL_MM = 1e-6
BEND_RADIUS_MM, LENGTH_MM = 40.0, 60.0


def polygon_area(radius: np.ndarray) -> float:
    """Area of the polygon with vertices radius_k (cos a_k, sin a_k), mm^2."""
    return float(0.5 * np.sin(2 * np.pi / radius.size) * np.sum(radius * np.roll(radius, -1)))


def cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z of the cross product of (..., 2) vectors."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def rays(na: int) -> np.ndarray:
    a = 2 * np.pi * np.arange(na) / na
    return np.column_stack([np.cos(a), np.sin(a)])


# --- the joint in its plane ---------------------------------------------------------------------------------
def test_radii_on_rays_known_answers():
    radius = 3.0 + 0.5 * np.cos(2 * np.pi * np.arange(12) / 12)
    np.testing.assert_allclose(radii_on_rays(radius[:, None] * rays(12)), radius, rtol=0, atol=ROUND_TOL)
    # a regular polygon turned by half a step: each ray meets the middle of a side, at R cos(h / 2)
    na, h = 16, 2 * np.pi / 16
    turned = 2.5 * np.column_stack([np.cos(np.arange(na) * h + h / 2), np.sin(np.arange(na) * h + h / 2)])
    np.testing.assert_allclose(radii_on_rays(turned), 2.5 * np.cos(h / 2), rtol=0, atol=ROUND_TOL)


@pytest.mark.parametrize("end, start", [(2.0, 3.0), (3.0, 2.0)])
def test_concentric_rings_are_closed_by_a_full_annulus(end, start):
    stitch = stitch_joint(np.full(24, end), np.full(24, start))
    assert stitch.triangles.shape == (48, 3) and not stitch.merged.any() and len(stitch.crossings) == 0
    areas = stitch.signed_areas()
    assert np.all(np.sign(areas) == np.sign(end - start))  # narrowing faces +T, widening -T
    np.testing.assert_allclose(areas.sum(), polygon_area(np.full(24, end)) - polygon_area(np.full(24, start)),
                               rtol=0, atol=ROUND_TOL)
    assert stitch.figures(0, 0.5).max_step_mm == pytest.approx(1.0, abs=ROUND_TOL)


def test_crossing_rings_get_the_crossing_as_a_vertex():
    na = 10  # rays every 36 degrees: cos(a) changes sign inside intervals 2 (72..108) and 7 (252..288)
    end, start = 3.0 + 0.5 * np.cos(2 * np.pi * np.arange(na) / na), np.full(na, 3.0)
    stitch = stitch_joint(end, start)
    assert stitch.crossing_interval.tolist() == [2, 7] and stitch.triangles.shape == (2 * na, 3)
    for x, k in zip(stitch.crossings, stitch.crossing_interval, strict=True):
        for ring in (end, start):  # on the chord k -> k+1 of both rings
            p0, p1 = ring[k] * rays(na)[k], ring[(k + 1) % na] * rays(na)[(k + 1) % na]
            np.testing.assert_allclose(cross2(p1 - p0, x - p0), 0.0, rtol=0, atol=ROUND_TOL)
    areas = stitch.signed_areas()
    np.testing.assert_allclose(areas.sum(), polygon_area(end) - polygon_area(start), rtol=0, atol=ROUND_TOL)
    # no overlap: the triangles' unsigned areas add up to the area between the rings, wedge by wedge
    def fan(p, q):
        return 0.5 * abs(p[0] * q[1] - p[1] * q[0])

    between = 0.0
    for k in range(na):
        k1 = (k + 1) % na
        u0, u1 = rays(na)[k], rays(na)[k1]
        if k in stitch.crossing_interval:
            x = stitch.crossings[list(stitch.crossing_interval).index(k)]
            between += abs(fan(end[k] * u0, x) - fan(start[k] * u0, x))
            between += abs(fan(x, end[k1] * u1) - fan(x, start[k1] * u1))
        else:
            between += abs(fan(end[k] * u0, end[k1] * u1) - fan(start[k] * u0, start[k1] * u1))
    np.testing.assert_allclose(np.abs(areas).sum(), between, rtol=0, atol=ROUND_TOL)


def test_equal_radii_share_vertices():
    same = stitch_joint(np.full(12, 3.0), np.full(12, 3.0))
    assert same.merged.all() and same.triangles.shape == (0, 3)
    na = 8  # cos(a) vanishes on the rays at 90 and 270 degrees: those vertices are shared, no crossing
    partial = stitch_joint(3.0 + 0.5 * np.cos(2 * np.pi * np.arange(na) / na), np.full(na, 3.0))
    assert partial.merged.tolist() == [False, False, True, False, False, False, True, False]
    assert len(partial.crossings) == 0 and partial.triangles.shape == (2 * na - 4, 3)
    assert not np.isin(partial.triangles, [2, 6]).any()  # link j's shared vertices are link j+1's


def test_rings_a_file_cannot_tell_apart_share_their_vertices():
    # steps of 3e-7 mm changing sign: float32 coordinates (a mesh file's) hold 3e-7 mm apart at 2 mm from the
    # origin but not at 20 mm; shared, they leave neither a crossing nor an annulus face to collapse on reading
    na = 12
    end = 3.0 + 3e-7 * np.cos(2 * np.pi * np.arange(na) / na)
    stitch = stitch_joint(end, np.full(na, 3.0))
    assert stitch.merged.all() and len(stitch.crossings) == 0 and stitch.triangles.shape == (0, 3)
    assert not stitch_joint(np.full(na, 3.0 + JOINT_MERGE_TOL_MM * 1.5), np.full(na, 3.0)).merged.any()


def test_vertices_a_file_would_merge_are_refused():
    vertices = np.array([[20.0, 0.0, 0.0], [20.0 + 3e-7, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(MeshError, match="1 vertex lies closer to another than a mesh file's float32"):
        check_distinct_when_written(vertices, "pose q=[0.1, 0.9]")
    check_distinct_when_written(vertices[[0, 2]], "pose q=[0.1, 0.9]")  # apart: no error


# --- a straight link and an arc: placement, steps and volume by hand ----------------------------------------
def arc_chain() -> LinkChain:
    """Straight (q = 0) to a 60 mm arc of radius 40 mm in the xz plane (q = 1), two links of 30 mm."""
    final = smooth_curve_from_samples(np.array([arc_point(s) for s in np.linspace(0.0, LENGTH_MM, 121)]))
    return LinkChain(blend_shapes(straight_initial_shape(final), final), np.array([0.0, 0.5, 1.0]))


def radius_field(final_rho, initial_radius=None, intervals=16) -> RadiusField:
    """Per-link splines with coefficients final_rho(angle) at every l; rho0 constant or the mean around."""
    links = []
    for lo, hi in ((0.0, 0.5), (0.5, 1.0)):
        knots = bb.open_knots([lo, hi], [10])
        row = final_rho(2 * np.pi * np.arange(intervals) / intervals)
        links.append(RadiusSpline(knots, np.tile(row, (len(knots) - 4, 1))))
    return RadiusField.from_links([0.0, 0.5, 1.0], tuple(links), radius_mm=initial_radius)


def arc_point(s: float) -> np.ndarray:
    return BEND_RADIUS_MM * np.array([1 - np.cos(s / BEND_RADIUS_MM), 0.0, np.sin(s / BEND_RADIUS_MM)])


def arc_tangent(s: float) -> np.ndarray:
    return np.array([np.sin(s / BEND_RADIUS_MM), 0.0, np.cos(s / BEND_RADIUS_MM)])


@pytest.fixture(scope="module")
def chain() -> LinkChain:
    return arc_chain()


@pytest.mark.parametrize(
    "q, joint, tip, step_sign",
    [
        ((0, 1), np.array([0, 0, 30.0]), np.array([0, 0, 30.0]) + arc_point(30.0), -1),  # r 2 then r 3
        ((1, 0), arc_point(30.0), arc_point(30.0) + 30.0 * arc_tangent(30.0), +1),  # r 3 then r 2
    ],
)
def test_straight_and_arc_links_placed_by_hand(chain, q, joint, tip, step_sign):
    body = pose_body(chain, radius_field(lambda a: np.full_like(a, 3.0), initial_radius=2.0), q, PoseSpec(0.5, 64))
    first, second = body.links
    np.testing.assert_allclose(first.start2world[:3, 3], 0.0, rtol=0, atol=ARC_TOL_MM)
    np.testing.assert_allclose(second.start2world[:3, 3], joint, rtol=0, atol=ARC_TOL_MM)
    np.testing.assert_allclose(second.start2world[:3, 2], arc_tangent(30.0 * q[0]), rtol=0, atol=ARC_TOL_MM)
    np.testing.assert_allclose(second.sweep.centers[-1], tip, rtol=0, atol=ARC_TOL_MM)
    # Pappus: a torus section holds pi r^2 times its centerline length, like the cylinder
    np.testing.assert_allclose(body.volume_expected, np.pi * (2.0**2 + 3.0**2) * 30.0, rtol=0, atol=1e-6)
    (step,) = body.joints
    assert step.annulus_faces == 128 and step.crossings == 0 and step.shared_vertices == 0
    np.testing.assert_allclose(step.max_step_mm, 1.0, rtol=0, atol=ROUND_TOL)
    annulus = body.faces[body.regions == Region.JOINT_STEP]
    corners = body.vertices[annulus]
    normals = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    along = normals @ second.start2world[:3, 2]
    assert np.all(np.sign(along) == step_sign)  # outward: +T where the body narrows, -T where it widens
    np.testing.assert_allclose(abs(along.sum()), polygon_area(np.full(64, 3.0)) - polygon_area(np.full(64, 2.0)),
                               rtol=0, atol=1e-9)
    plane = (corners.reshape(-1, 3) - joint) @ second.start2world[:3, 2]
    np.testing.assert_allclose(plane, 0.0, rtol=0, atol=ARC_TOL_MM)


def test_equal_radii_at_a_joint_share_the_ring(chain):
    body = pose_body(chain, radius_field(lambda a: np.full_like(a, 3.0), initial_radius=3.0), (0, 1), PoseSpec(0.5, 64))
    (step,) = body.joints
    assert step.shared_vertices == 64 and step.annulus_faces == 0 and not np.any(body.regions == Region.JOINT_STEP)
    rings = sum(link.sweep.xy.shape[0] for link in body.links)
    assert body.vertices.shape[0] == (rings - 1) * 64 + 2  # one joint ring, two cap centres


@pytest.mark.parametrize("offset_mm", [0.0, 0.4, -0.4])
def test_crossing_steps_stay_one_watertight_body(chain, offset_mm):
    # rho0 is the mean of rhof around: the step (q0 - q1)(rhof - rho0) changes sign twice around the joint
    field = radius_field(lambda a: 3.0 + 0.5 * np.cos(a))
    body = pose_body(chain, field, (0, 1), PoseSpec(0.5, 64, offset_mm))
    (step,) = body.joints
    # offset 0: rhof = rho0 exactly on the rays at 90 and 270 deg (shared); an offset moves them off the rays
    assert (step.shared_vertices, step.crossings) == ((2, 0) if offset_mm == 0 else (0, 2))
    report = inspect_mesh(body.vertices, body.faces)
    assert report.watertight and report.winding_consistent and report.vertex_manifold
    assert (report.bodies, report.voids, report.euler, report.degenerate_faces) == (1, 0, 2, 0)
    joint = body.links[1].sweep
    ring = joint.centers[0] + joint.xy[0] @ joint.frames[0][:, :2].T
    radial = (ring - joint.centers[0]) @ joint.frames[0][:, :2]  # the joint ring sits on the rays a_k
    np.testing.assert_allclose(cross2(radial, rays(64)), 0.0, rtol=0, atol=ROUND_TOL)


# --- the sample case ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    # its own build, not a copy of the README's demo build: make test-fast runs the quick tests below without the
    # README's commands, and that build (with its report, in a child) cost it 51 s at load 7 against about 4 s here
    out = tmp_path_factory.mktemp("pose") / "build"
    result = runner.invoke(app, ["build", str(DEMO), "--out", str(out), "--jobs", "1"])  # no pool: tests/conftest.py
    assert result.exit_code == 0, result.output
    from softdesign.pipeline.api import build_through

    return build_through(DEMO, out)


def _run_pose(demo, q: str, output: Path, *extra: str):
    args = ["pose", str(DEMO), "--q", q, "--output", str(output), "--out", str(demo.build_dir), *extra]
    return runner.invoke(app, args)


@pytest.mark.slow
@pytest.mark.parametrize("q", [0.0, 0.5, 1.0])
def test_equal_q_reproduces_the_build_mesh(demo, tmp_path, q):
    output = tmp_path / "pose.stl"
    result = _run_pose(demo, f"{q:g}", output)
    assert result.exit_code == 0, result.output
    assert "rings shared (no radial step)" in result.stdout
    mine = trimesh.load(output, process=True)
    built = trimesh.load(demo.build_dir / f"meshes/q_{q:.3f}.stl", process=True)
    difference = compare_meshes(mine.vertices, mine.faces, built.vertices, built.faces)
    assert difference.distance_max_mm < EQUAL_Q_TOL_MM
    assert difference.watertight and mine.body_count == 1


def test_mixed_q_links_start_on_the_previous_links_end_frame(demo):
    chain, field = demo.results["kinematics"].chain, demo.results["fit"].field
    export = demo.case.export
    for q in ((0.0, 1.0, 0.0, 1.0), (0.2, 0.8, 1.0, 0.5)):
        body = pose_body(chain, field, q, PoseSpec(export.spacing_mm, export.angular_count))
        expected = chain.base2world(q)
        for link, transform in zip(body.links, chain.transforms(q), strict=True):
            sweep = link.sweep
            np.testing.assert_allclose(link.start2world, expected, rtol=0, atol=PLACEMENT_TOL_MM)
            np.testing.assert_allclose(sweep.centers[0], expected[:3, 3], rtol=0, atol=PLACEMENT_TOL_MM)
            np.testing.assert_allclose(sweep.frames[0], expected[:3, :3], rtol=0, atol=PLACEMENT_TOL_MM)
            expected = expected @ transform  # the link's end frame: the next link's {S}
            np.testing.assert_allclose(sweep.centers[-1], expected[:3, 3], rtol=0, atol=PLACEMENT_TOL_MM)
            np.testing.assert_allclose(sweep.frames[-1], expected[:3, :3], rtol=0, atol=PLACEMENT_TOL_MM)
            # the piece itself is S(q_j) moved rigidly: seen from its {S} it is c(q_j, l) seen from F(q_j, l_j)
            curve = chain.shape.curve_at(link.q)
            start2build = curve.poses([link.l_start])[0]
            local = (sweep.centers - link.start2world[:3, 3]) @ link.start2world[:3, :3]
            own = (curve.points(sweep.l) - start2build[:3, 3]) @ start2build[:3, :3]
            np.testing.assert_allclose(local, own, rtol=0, atol=PLACEMENT_TOL_MM)


def test_mixed_q_steps_are_closed_by_a_reported_annulus(demo, tmp_path):
    q = (0.0, 1.0, 0.0, 1.0)
    result = _run_pose(demo, "0,1,0,1", tmp_path / "pose.stl", "--json")
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    field, na = demo.results["fit"].field, demo.case.export.angular_count
    a = 2 * np.pi * np.arange(na) / na
    body = pose_body(demo.results["kinematics"].chain, field, q, PoseSpec(demo.case.export.spacing_mm, na))
    annulus = body.vertices[body.faces[body.regions == Region.JOINT_STEP]]
    joints = [link.start2world for link in body.links[1:]]
    nearest = np.argmin([np.linalg.norm(annulus.mean(axis=1) - pose[:3, 3], axis=1) for pose in joints], axis=0)
    for j, (joint, joint_pose) in enumerate(zip(payload["joints"], joints, strict=True)):
        l = field.breaks[j + 1]
        end = field.link_spline(j, q[j]).evaluate_grid([l], a)[0]
        start = field.link_spline(j + 1, q[j + 1]).evaluate_grid([l], a)[0]
        assert np.max(np.abs(end - start)) > 0.1  # the fit's rho0 and rhof differ here by more than round-off
        np.testing.assert_allclose(joint["max_step_mm"], np.max(np.abs(end - start)), rtol=0, atol=PLACEMENT_TOL_MM)
        corners = annulus[nearest == j]
        assert len(corners) == joint["annulus_faces"] > 0
        center, axis = joint_pose[:3, 3], joint_pose[:3, 2]
        np.testing.assert_allclose((corners.reshape(-1, 3) - center) @ axis, 0.0, rtol=0, atol=PLACEMENT_TOL_MM)
        # flat, wound outward (+T where link j is the wider), covering exactly the step between the rings (where
        # they are within JOINT_MERGE_TOL_MM they share link j+1's vertex: no step there)
        along = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]) @ axis / 2
        shared = np.where(np.abs(end - start) <= JOINT_MERGE_TOL_MM, start, end)
        np.testing.assert_allclose(along.sum(), polygon_area(shared) - polygon_area(start), rtol=0, atol=1e-9)
        np.testing.assert_allclose(np.abs(along).sum(), joint["annulus_area_mm2"], rtol=0, atol=1e-9)
    written = trimesh.load(tmp_path / "pose.stl", process=True)
    assert written.is_watertight and written.is_winding_consistent and written.body_count == 1
    np.testing.assert_allclose(written.volume, payload["volume_mm3"], rtol=1e-6)  # float32 coordinates in the STL


@pytest.mark.slow
def test_a_coil_posed_with_nearly_equal_rings_reads_back_closed(tmp_path):
    # the sample cohort's coil at these q has rings 3e-7 mm apart at joint 1|2: written before the joints shared
    # them, the STL read back with two edges in four faces (Euler 3)
    case, out = REPO / "configs" / "cohort" / "coil.yaml", tmp_path / "build"
    assert runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"]).exit_code == 0
    result = runner.invoke(app, ["pose", str(case), "--q", "0.12,0.67,0.65,0.62,0.38", "--output",
                                 str(tmp_path / "pose.stl"), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert sum(joint["shared_vertices"] for joint in payload["joints"]) > 0
    written = trimesh.load(tmp_path / "pose.stl", process=True)
    assert written.is_watertight and written.is_winding_consistent and written.euler_number == 2
    assert len(written.vertices) == payload["vertices"]  # no vertex merged on reading


@pytest.mark.parametrize(
    "q, message",
    [
        ("0,1,1", "3 values for 4 links"),
        ("1.5", "value 1 of '1.5' is 1.5, expected a number in [0, 1]"),
        ("0,-0.1,0,1", "expected a number in [0, 1]"),
        ("half", "'half' of 'half' is not a number"),
        ("0,,1,1", "value 2 '' of '0,,1,1' is not a number"),
        ("nan", "expected a number in [0, 1]"),
    ],
)
def test_bad_q_exits_2(demo, tmp_path, q, message):
    result = _run_pose(demo, q, tmp_path / "pose.stl")
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert not (tmp_path / "pose.stl").exists()


@pytest.mark.parametrize("name", ["pose.xyz", "pose"])
def test_unknown_output_suffix_exits_2(demo, tmp_path, name):
    result = _run_pose(demo, "0.5", tmp_path / name)
    assert result.exit_code == 2
    assert "unknown mesh format" in result.output and ".stl, .ply, .obj, .glb" in result.output
    assert list(tmp_path.iterdir()) == []


@pytest.fixture(scope="module")
def hollow_case(tmp_path_factory) -> Path:
    """The sample case with a 1 mm wall and a 1 mm port."""
    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    case["export"].update(wall_mm=1.0, port_mm=1.0)
    path = tmp_path_factory.mktemp("hollow") / "hollow.yaml"
    path.write_text(yaml.safe_dump(case))
    return path


@pytest.fixture(scope="module")
def hollow_build(hollow_case, tmp_path_factory) -> Path:
    """``hollow_case`` built once for the two tests that pose it: each poses a copy (pose builds, cached, into the
    folder it is given, so the copy's stages are all reused and only the pose is made)."""
    out = tmp_path_factory.mktemp("hollow-build") / "build"
    result = runner.invoke(app, ["build", str(hollow_case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return out


@pytest.mark.slow
def test_hollow_pose_with_equal_q_is_the_builds_hollow_mesh(hollow_case, hollow_build, tmp_path):
    out = shutil.copytree(hollow_build, tmp_path / "build")
    args = ["pose", str(hollow_case), "--q", "1", "--output", str(tmp_path / "p.stl"), "--out", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "ported body" in result.stdout
    mine = trimesh.load(tmp_path / "p.stl", process=True)
    built = trimesh.load(out / "meshes/q_1.000.stl", process=True)
    difference = compare_meshes(mine.vertices, mine.faces, built.vertices, built.faces)
    assert difference.distance_max_mm < EQUAL_Q_TOL_MM
    assert mine.volume == pytest.approx(built.volume, rel=1e-12) and len(mine.faces) == len(built.faces)


@pytest.mark.slow
def test_hollow_pose_with_mixed_q_is_one_ported_body_with_its_walls_reported(hollow_case, hollow_build, tmp_path):
    out = shutil.copytree(hollow_build, tmp_path / "build")
    args = [
        "pose", str(hollow_case), "--q", "0,1,0,1", "--output", str(tmp_path / "p.ply"), "--out", str(out), "--json"
    ]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert payload["kind"] == "ported" and payload["watertight"] and payload["bodies"] == 1
    assert abs(payload["volume_rel_error"]) < 0.005
    for joint in payload["joints"]:  # a 1 mm wall less each joint's radial step, at the thinnest
        assert joint["max_step_mm"] > 0.1
        assert 1.0 - joint["max_step_mm"] - 0.01 <= joint["min_wall_mm"] <= 1.0 - joint["max_step_mm"] + 0.01
    written = trimesh.load(tmp_path / "p.ply", process=False)
    regions = written.metadata["_ply_raw"]["face"]["data"]["region"]
    assert {Region.CHAMBER, Region.CHAMBER_CAP, Region.PORT, Region.JOINT_STEP} <= set(regions.tolist())
    merged = trimesh.load(tmp_path / "p.ply", process=True)
    assert merged.is_watertight and merged.body_count == 1 and merged.euler_number == 2


@pytest.mark.parametrize("port_mm", [0.0, 0.5])
def test_hollow_pose_of_a_straight_and_an_arc_link_by_hand(chain, port_mm):
    # r 2 then r 3 (a 1 mm step), wall 1.5: the chamber is r 0.5 then 1.5, 1.5 mm short of both ends
    field = radius_field(lambda a: np.full_like(a, 3.0), initial_radius=2.0)
    w = 1.5
    body = pose_body(chain, field, (0, 1), PoseSpec(0.5, 64, wall_mm=w, port_mm=port_mm))
    chamber = np.pi * (0.5**2 + 1.5**2) * (30.0 - w)  # Pappus again for the arc's half
    port = np.pi * (port_mm / 2) ** 2 * w
    np.testing.assert_allclose(body.volume_expected, np.pi * (2.0**2 + 3.0**2) * 30.0 - chamber - port,
                               rtol=0, atol=1e-6)
    assert body.kind == ("ported" if port_mm else "hollow")
    assert (body.report.bodies, body.report.euler) == (1, 2 if port_mm else 4)
    assert abs(body.report.volume_rel_error) < 0.005
    (joint,) = body.joints
    np.testing.assert_allclose(joint.min_wall_mm, w - 1.0, rtol=0, atol=1e-9)


def test_a_step_that_would_break_through_the_wall_is_refused(chain):
    from softdesign.errors import MeshError

    field = radius_field(lambda a: np.full_like(a, 3.0), initial_radius=2.0)
    with pytest.raises(MeshError, match=r"joint 0\|1 at l=0.5000: the links' radii step by up to 1.000 mm, "
                                        r"which leaves a wall of 0.100 mm of the 1.1 mm asked"):
        pose_body(chain, field, (0, 1), PoseSpec(0.5, 64, wall_mm=1.1))


def test_help_names_the_options():
    result = runner.invoke(app, ["pose", "--help"])
    assert result.exit_code == 0
    assert "--q" in result.output and "--output" in result.output and "--out" in result.output
