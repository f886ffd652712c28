"""`softdesign report`: the page for the sample case and the real VMTK aorta, its images, table and checks.

Each case is built into a temporary folder first, then reported.  The page
is read back with an HTML parser written here (not the package's own), the
images with Pillow, the figures against ``manifest.json`` with a JSON-pointer
walk written here.
"""

from __future__ import annotations

import hashlib
import html
import json
import shutil
from dataclasses import replace
from html.parser import HTMLParser
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest
import typer
from PIL import Image
from typer.testing import CliRunner

from softdesign.errors import ConfigError
from softdesign.pipeline.api import build_through
from softdesign.pipeline.manifest import STALE_TEXT
from softdesign.pipeline.owned import REPORT_MARKER
from softdesign.pipeline.versions import software_versions
from softdesign.report.interactive import DISPLAY_TOLERANCE_MM, DIV_ID, JS_NAME
from softdesign.report.writer import (
    EXPECTED_SIZES,
    LOG,
    PAGE,
    REPORT_DIR,
    ReportOptions,
    commit_folder,
    write_report,
)
from tests.helpers.paths import REPO
from tests.helpers.shared_builds import aorta_build, demo_build_copy, shared_build_copy

#: Builds and reports the sample case and the aorta: `make test-fast` leaves these out.
pytestmark = pytest.mark.slow

DEMO_CASE = REPO / "configs" / "demo.yaml"
#: The page shows figures to 6 significant digits: the text may differ from the exact value by half a unit in the 6th.
SHOWN_RTOL = 5e-6
#: Distances recomputed from the kept radius field: the same algorithm as the fit stage, on a rebuilt
#: (knot-inserted per link) spline, so they agree to rounding of ~5 mm radii.
DISTANCE_ATOL_MM = 1e-9
#: kinematics.json and the rebuilt chain evaluate the same spline the same way.
KINEMATICS_ATOL = 1e-9
#: The reports of tests about the checks, the banner or one figure, not the figures' sampling: 3 GIF frames, 3 views
#: and 5 q of the kinematics plot (the report's defaults: 26, 21 and 41).
FEW_FRAMES = ReportOptions(gif_frames=3, view_frames=3, q_samples=5)
#: Chamber distance for the demo's PCC panel, mm (its largest curvature is 0.097 /mm: kappa d < 1).
DEMO_PCC_D = 5.0


class PageParser(HTMLParser):
    """Images, links, key-figure cells and check rows of the report page."""

    def __init__(self) -> None:
        super().__init__()
        self.images: list[dict[str, str]] = []
        self.links: list[str] = []
        self.figures: list[dict[str, str]] = []
        self.rows: list[list[str]] = []
        self._cell: dict[str, str] | None = None
        self._row: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.links += [v for k, v in attrs if k in ("src", "href") and v is not None]
        if tag == "img":
            self.images.append(attributes)
        elif tag == "tr":
            self._row = []
        elif tag == "td":
            self._cell = {**attributes, "text": ""}

    def handle_data(self, data):
        if self._cell is not None:
            self._cell["text"] += data

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            if "data-pointer" in self._cell:
                self.figures.append(self._cell)
            if self._row is not None:
                self._row.append(self._cell["text"])
            self._cell = None
        elif tag == "tr" and self._row is not None:
            self.rows.append(self._row)
            self._row = None


def parse_page(report_dir: Path) -> PageParser:
    parser = PageParser()
    parser.feed((report_dir / PAGE).read_text(encoding="utf-8"))
    return parser


def at_pointer(document, pointer: str):
    """The value at an RFC 6901 pointer (independent of the package's resolver)."""
    for token in pointer.lstrip("/").split("/"):
        token = token.replace("~1", "/").replace("~0", "~")
        document = document[int(token)] if isinstance(document, list) else document[token]
    return document


def tree_hashes(folder: Path) -> dict[str, str]:
    """The report's files with their hashes (not its marker, which lists them: issue 36)."""
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())
            if p.name != REPORT_MARKER}


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The README's demo build (made once per run, tests/helpers/shared_builds.py), copied, with this file's report."""
    build_dir = demo_build_copy(tmp_path_factory, tmp_path_factory.mktemp("demo") / "build")
    result = write_report(build_dir, ReportOptions(pcc_d=(DEMO_PCC_D,)))
    return build_dir, result


@pytest.fixture(scope="module")
def aorta(tmp_path_factory, aorta_dir):
    """The run's shared aorta build (four exported q; tests/helpers/shared_builds.py), copied, with this file's
    report."""
    build_dir = shared_build_copy(aorta_build(tmp_path_factory), tmp_path_factory.mktemp("aorta") / "build")
    return build_dir, write_report(build_dir)


@pytest.fixture(params=["demo", "aorta"])
def built(request):
    return request.getfixturevalue(request.param)


def test_every_image_is_a_valid_file_of_the_size_the_page_states(built):
    build_dir, _ = built
    report_dir = build_dir / REPORT_DIR
    page = parse_page(report_dir)
    assert {"morph.png", "surfaces.png", "fit_residuals.png", "fit_distances.png", "kinematics.png", "morph.gif"} <= {
        image["src"] for image in page.images
    }
    for image in page.images:
        file = report_dir / image["src"]
        with Image.open(file) as opened:
            opened.verify()  # a truncated or corrupt file raises here
        with Image.open(file) as opened:
            assert opened.format == ("GIF" if file.suffix == ".gif" else "PNG")
            assert opened.size == EXPECTED_SIZES[file.name] == (int(image["width"]), int(image["height"]))
            assert opened.format != "GIF" or opened.n_frames > 2


def test_the_page_links_only_to_files_beside_it_and_every_file_is_linked(built):
    build_dir, result = built
    report_dir = build_dir / REPORT_DIR
    page = parse_page(report_dir)
    files = [link for link in page.links if not link.startswith("#")]
    assert files, "the page shows no image"
    for link in files:
        assert "://" not in link and not link.startswith("/") and ".." not in link, link  # no network, no escape
        assert (report_dir / link).is_file(), link
    # and report.log beside it: the folder's path and the times, which the page leaves out
    written = sorted(p.name for p in report_dir.iterdir() if p.name != REPORT_MARKER)
    assert sorted(set(files) | {PAGE, LOG}) == written == sorted(result.files)
    anchors = {link[1:] for link in page.links if link.startswith("#")}
    text = (report_dir / PAGE).read_text(encoding="utf-8")
    assert all(f'id="{anchor}"' in text for anchor in anchors)


def test_every_figure_in_the_table_equals_the_manifest(built):
    build_dir, _ = built
    manifest = json.loads((build_dir / "manifest.json").read_text())
    figures = parse_page(build_dir / REPORT_DIR).figures
    pointers = {f["data-pointer"] for f in figures}
    fit = {f"/metrics/fit/{key}" for key in ("rms_mm", "p95_mm", "p99_mm", "max_mm", "holdout_rms_mm", "max_rho_kappa")}
    meshes = [i for i, o in enumerate(manifest["outputs"]) if o["path"].endswith(".stl")]
    assert fit <= pointers and meshes
    assert {f"/outputs/{i}/{key}" for i in meshes for key in ("volume_mm3", "area_mm2", "watertight")} <= pointers
    for cell in figures:
        value = at_pointer(manifest, cell["data-pointer"])
        assert json.loads(cell["data-value"]) == value, cell["data-pointer"]
        if isinstance(value, bool):
            assert cell["text"] == ("yes" if value else "no")
        elif isinstance(value, (int, float)):
            np.testing.assert_allclose(float(cell["text"]), value, rtol=SHOWN_RTOL, atol=0,
                                       err_msg=cell["data-pointer"])


def test_every_check_passes_and_each_mesh_is_checked(built):
    build_dir, result = built
    export = json.loads((build_dir / "export" / "summary.json").read_text())
    rows = [r for r in parse_page(build_dir / REPORT_DIR).rows if len(r) == 5 and r[-1] in ("pass", "FAIL")]
    assert len(rows) == result.checks_total == result.checks_passed
    for mesh in export["meshes"]:
        names = {r[1] for r in rows if r[0] == mesh}
        assert {"watertight", "consistent winding", "one body", "volume vs integrated volume"} <= names, mesh
    manifest = json.loads((build_dir / "manifest.json").read_text())
    assert {o["path"] for o in manifest["outputs"]} <= {r[0] for r in rows if r[1].startswith("file as recorded")}


def test_inputs_and_software_are_listed(built):
    build_dir, _ = built
    manifest = json.loads((build_dir / "manifest.json").read_text())
    rows = parse_page(build_dir / REPORT_DIR).rows
    for entry in manifest["inputs"]:
        assert [entry["path"], entry["sha256"], str(entry["bytes"])] in rows
    # the Software table: package, version the manifest recorded, version that drew the page
    for name, version in manifest["software"].items():
        assert [name, version, software_versions()[name]] in rows, name
    assert ["matplotlib", "-", metadata.version("matplotlib")] in rows


def test_aorta_report_notes_the_missing_pcc_panel(aorta):
    build_dir, _ = aorta
    text = (build_dir / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    assert "pcc_chambers.png" not in text and "--pcc-d" in text


def test_demo_report_draws_pcc_chambers(demo):
    build_dir, result = demo
    assert "pcc_chambers.png" in result.files
    with Image.open(build_dir / REPORT_DIR / "pcc_chambers.png") as image:
        assert image.size == EXPECTED_SIZES["pcc_chambers.png"]


def test_histogram_distances_are_the_manifests(demo):
    from softdesign.fitting.metrics import summarize_distances
    from softdesign.report.build_folder import load_build
    from softdesign.report.fit_figures import true_distances

    data = load_build(demo[0])
    kept = data.fit.points["distance"]
    # the fit keeps the distances its metrics summarize; a folder without them (older) has them measured again
    rebuilt = replace(data, fit=replace(data.fit, points={k: v for k, v in data.fit.points.items() if k != "distance"}))
    fit = data.manifest["metrics"]["fit"]
    # point by point, in vertex order: each kept distance is its own vertex's
    np.testing.assert_allclose(true_distances(data), true_distances(rebuilt), rtol=0, atol=DISTANCE_ATOL_MM)
    for distances in (true_distances(data), true_distances(rebuilt)):
        found = summarize_distances(distances)
        assert found.count == fit["points"]["kept"] == np.isfinite(kept).sum()
        for key in ("rms_mm", "p95_mm", "p99_mm", "max_mm"):
            np.testing.assert_allclose(getattr(found, key), fit[key], rtol=0, atol=DISTANCE_ATOL_MM, err_msg=key)


def test_kinematics_series_at_the_export_q_equals_kinematics_json(demo):
    from softdesign.report.build_folder import load_build
    from softdesign.report.kinematics_figures import kinematics_series

    data = load_build(demo[0])
    series = kinematics_series(data.kinematics.chain, data.export_q, samples=5)
    assert series.q[0] == 0.0 and series.q[-1] == 1.0 and np.all(np.diff(series.q) > 0)
    for pose in data.kinematics.document["poses"]:
        row = int(np.flatnonzero(series.q == pose["q"][0])[0])
        for j, link in enumerate(pose["links"]):
            expected = (link["poe"]["theta1"], link["poe"]["theta2"], link["length"], *link["stretch"])
            found = (series.theta1[row, j], series.theta2[row, j], series.length[row, j],
                     series.stretch_min[row, j], series.stretch_max[row, j])
            np.testing.assert_allclose(found, expected, rtol=0, atol=KINEMATICS_ATOL)
            assert series.curvature_max[row, j] == pytest.approx(link["curvature_per_mm"][1], abs=KINEMATICS_ATOL)


def plot_area_variance(figure, ax) -> float:
    """Pixel variance inside the axes' frame (spines, ticks and labels excluded) of the figure's PNG."""
    import io

    from softdesign.report.plotting import png_bytes

    data = png_bytes(figure)
    figure.canvas.draw()
    box = ax.get_window_extent()
    with Image.open(io.BytesIO(data)) as image:
        pixels = np.asarray(image.convert("L"), float)
    inset = 3  # pixels: keep the spines out
    top, bottom = pixels.shape[0] - int(box.y1) + inset, pixels.shape[0] - int(box.y0) - inset
    return float(pixels[top:bottom, int(box.x0) + inset:int(box.x1) - inset].var())


#: Pixel variance (grey levels squared) below which a plot area counts as blank.
BLANK_VARIANCE = 1.0


def test_a_drawn_plot_is_not_blank_and_an_empty_one_is(demo):
    from softdesign.report.build_folder import load_build
    from softdesign.report.morph_figures import draw_view, morph_curves
    from softdesign.report.plotting import link_colours, new_figure
    from softdesign.report.projection import axis_views

    chain = load_build(demo[0]).kinematics.chain
    drawn = new_figure((4.0, 3.0))
    ax = drawn.add_subplot(1, 1, 1)
    draw_view(ax, morph_curves(chain, [0.0, 1.0]), axis_views()[1], link_colours(chain.count), arm=3.0)
    assert plot_area_variance(drawn, ax) > BLANK_VARIANCE
    empty = new_figure((4.0, 3.0))
    empty_ax = empty.add_subplot(1, 1, 1)
    empty_ax.set(xlabel="x (mm)", ylabel="z (mm)", title="no data")
    assert plot_area_variance(empty, empty_ax) < BLANK_VARIANCE  # the check fails a plot without data


def test_same_build_gives_the_same_report_bytes(demo, tmp_path):
    build_dir, _ = demo
    before = tree_hashes(build_dir / REPORT_DIR)
    copy = tmp_path / "another-name"  # the page names no folder: report.log does, with the times
    shutil.copytree(build_dir, copy)
    shutil.rmtree(copy / REPORT_DIR)
    write_report(copy, ReportOptions(pcc_d=(DEMO_PCC_D,)))
    after = tree_hashes(copy / REPORT_DIR)
    assert after.keys() == before.keys() and LOG in after
    assert [name for name in after if after[name] != before[name] and name != LOG] == []


def test_tampered_outputs_fail_their_checks(demo, tmp_path):
    copy = tmp_path / "tampered"
    shutil.copytree(demo[0], copy)
    summary_file = copy / "export" / "summary.json"
    summary = json.loads(summary_file.read_text())
    mesh = sorted(summary["meshes"])[0]
    summary["meshes"][mesh]["watertight"] = False
    summary["meshes"][mesh]["volume_rel_error"] = 0.02
    summary_file.write_text(json.dumps(summary))
    result = write_report(copy, FEW_FRAMES)
    checks = [r for r in parse_page(copy / REPORT_DIR).rows if r[-1:] in (["FAIL"], ["pass"])]
    assert [r[-1] for r in checks[:3]] == ["FAIL"] * 3 and "FAIL" not in [r[-1] for r in checks[3:]]  # failures first
    text = (copy / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    # and in the checks' tally under the verdict, opened on its failures (the build's warnings are the banner's)
    box = text[text.index('<details class="tally" id="checks" open>'):text.index("<nav>")]
    assert f"Checks: {result.checks_passed} of {result.checks_total} passed" in box and f"{mesh}: watertight" in box
    failed = {(r[0], r[1]) for r in checks if r[-1] == "FAIL"}
    assert failed == {(mesh, "watertight"), (mesh, "volume vs integrated volume"),
                      ("export/summary.json", "file as recorded (sha256)")}
    assert result.checks_total - result.checks_passed == 3


def test_a_stale_stage_is_noted_on_the_page(demo, tmp_path):
    # what `softdesign fit` records when the export on disk was made from another fit (tests/pipeline/test_build.py)
    copy = tmp_path / "stale"
    shutil.copytree(demo[0], copy)
    manifest_file = copy / "manifest.json"
    manifest = json.loads(manifest_file.read_text())
    for stage in manifest["stages"]:
        if stage["name"] == "export":
            stage["stale"] = True
    # as the build records it (pipeline/manifest.py): the stale stage is one of the manifest's warnings
    manifest["warnings"].append({"stage": "export", "code": "stale", "place": "", "text": STALE_TEXT,
                                 "kind": "warning"})
    manifest_file.write_text(json.dumps(manifest))
    write_report(copy, FEW_FRAMES)
    text = (copy / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    banner = text[text.index('<div class="banner"'):text.index("<nav>")]  # the warnings sit above every section
    assert html.escape(f"export: {STALE_TEXT}") in banner and text.count(html.escape(STALE_TEXT)) == 1
    assert html.escape(STALE_TEXT) not in (demo[0] / REPORT_DIR / PAGE).read_text(encoding="utf-8")


def test_a_failed_write_leaves_the_previous_report(tmp_path):
    target = tmp_path / REPORT_DIR
    commit_folder(target, {PAGE: b"old page", "a.png": b"old image"})
    with pytest.raises(FileNotFoundError):
        commit_folder(target, {PAGE: b"new page", "no/such/folder.png": b"x"})
    assert tree_hashes(target) == {PAGE: hashlib.sha256(b"old page").hexdigest(),
                                   "a.png": hashlib.sha256(b"old image").hexdigest()}
    assert sorted(p.name for p in tmp_path.iterdir()) == [REPORT_DIR]  # no temporary folder left
    commit_folder(target, {PAGE: b"new page"})
    assert tree_hashes(target) == {PAGE: hashlib.sha256(b"new page").hexdigest()}  # replaced as a whole


def test_a_build_without_fit_gets_a_report_with_the_centerline_only(tmp_path):
    build_dir = tmp_path / "build"
    build_through(DEMO_CASE, build_dir, target="kinematics")
    result = write_report(build_dir, ReportOptions(gif_frames=4))
    assert set(result.files) == {PAGE, "morph.png", "kinematics.png", "design.png", "morph.gif", JS_NAME, LOG}
    text = (build_dir / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    assert "no fit in this build folder" in text and "no export in this build folder" in text
    with Image.open(build_dir / REPORT_DIR / "morph.gif") as gif:
        assert gif.n_frames == 4 and gif.size == EXPECTED_SIZES["morph.gif"]


def report_app() -> typer.Typer:
    """An app with the report command, registered the way softdesign.cli registers commands."""
    from softdesign.cli.report import report

    app = typer.Typer()
    app.command()(report)
    app.command("noop")(lambda: None)  # a second command keeps `report` a named subcommand, as in softdesign
    return app


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["report", "{missing}"], "not a build folder (no manifest.json)"),
        (["report", "{build}", "--pcc-d", "ten"], "--pcc-d value 1: 'ten' is not a number"),
        (["report", "{build}", "--pcc-d", "-3"], "--pcc-d value 1: -3 mm, expected > 0"),
        (["report", "{build}", "--pcc-d", "1,2"], "the build has 4 link(s)"),
    ],
)
def test_cli_bad_input_exits_2_with_a_message(demo, tmp_path, args, message):
    filled = [a.format(missing=tmp_path / "nothing", build=demo[0]) for a in args]
    before = tree_hashes(demo[0] / REPORT_DIR)
    result = CliRunner().invoke(report_app(), filled)
    assert result.exit_code == 2, result.output
    assert message in result.output and "Traceback" not in result.output
    assert tree_hashes(demo[0] / REPORT_DIR) == before


def test_a_bad_pcc_count_is_refused_before_any_figure(demo, monkeypatch):
    """The count of --pcc-d is checked once the build is loaded: no figure is drawn for a report it refuses."""
    import softdesign.report.writer as writer

    def drawn(*_args, **_kwargs):
        raise AssertionError("a figure was drawn before the --pcc-d count was checked")

    monkeypatch.setattr(writer, "_slow_parts", drawn)
    monkeypatch.setattr(writer, "_view_section", drawn)
    with pytest.raises(ConfigError, match=r"--pcc-d: got 2 distances, the build has 4 link\(s\)"):
        write_report(demo[0], ReportOptions(pcc_d=(1.0, 2.0)))


def test_cli_help_names_the_option():
    result = CliRunner().invoke(report_app(), ["report", "--help"])
    assert result.exit_code == 0 and "--pcc-d" in result.output and "BUILD_DIR" in result.output


def test_principal_view_looks_at_the_broad_side_of_a_planar_curve():
    from softdesign.report.projection import principal_view

    t = np.linspace(0.0, 1.0, 50)
    # in the x-z plane; z = cos is uncorrelated with x, so x is exactly the axis of largest spread
    points = np.column_stack([80.0 * t, np.zeros_like(t), 10.0 * np.cos(2.0 * np.pi * t)])
    view = principal_view(points, points[-1] - points[0])
    np.testing.assert_allclose(view.view2world.T @ view.view2world, np.eye(3), rtol=0, atol=1e-12)
    assert np.linalg.det(view.view2world) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(abs(view.view2world[:, 2] @ [0.0, 1.0, 0.0]), 1.0, rtol=0, atol=1e-12)
    screen = view.project(points)
    np.testing.assert_allclose(screen[0], [0.0, 0.0], rtol=0, atol=1e-12)  # the origin is the first point
    np.testing.assert_allclose(screen[-1], [80.0, 0.0], rtol=0, atol=1e-9)  # right runs from first to last point


def test_shading_order_and_culling_of_two_facing_triangles():
    from softdesign.report.projection import AMBIENT, LIGHT_VIEW, View, shaded_triangles

    view = View(np.eye(3), ("x", "y"))
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 5], [1, 0, 5], [0, 1, 5]], float)
    faces = np.array([[3, 4, 5], [0, 2, 1]])  # near face towards the viewer (+z), far face away from it
    shaded = shaded_triangles(vertices, faces, view)
    assert shaded.face_index.tolist() == [1, 0]  # far first
    facing = AMBIENT + (1.0 - AMBIENT) * LIGHT_VIEW[2] / np.linalg.norm(LIGHT_VIEW)
    np.testing.assert_allclose(shaded.brightness, [facing, facing], rtol=0, atol=1e-12)  # two-sided
    assert shaded_triangles(vertices, faces, view, cull=True).face_index.tolist() == [0]


def test_tube_vertices_lie_at_the_fitted_radius_and_face_outwards(demo):
    from softdesign.report.build_folder import load_build
    from softdesign.report.surface_figures import tube_mesh

    data = load_build(demo[0])
    chain, field = data.kinematics.chain, data.fit.field
    vertices, faces, face_l = tube_mesh(chain, field, 0.0, spacing_mm=2.0, angles=16)
    curve = chain.shape.curve_at(0.0)
    rings = vertices.reshape(-1, 16, 3)
    l = np.linspace(0.0, 1.0, len(rings))
    radius = np.linalg.norm(rings - curve.points(l)[:, None, :], axis=2)
    angles = np.linspace(0.0, 2.0 * np.pi, 16, endpoint=False)
    np.testing.assert_allclose(radius, field.evaluate_grid(0.0, l, angles), rtol=0, atol=1e-9)
    tri = vertices[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    outward = tri.mean(axis=1) - curve.points(face_l)
    assert np.all(np.einsum("ij,ij->i", normals, outward) > 0.0)


def test_a_killed_runs_temporary_folder_is_removed_a_running_ones_kept(tmp_path):
    import subprocess
    import sys

    finished = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = tmp_path / f".report-{finished.stdout.strip()}-0123456789ab"  # that process has exited
    alive = tmp_path / f".report-{__import__('os').getpid()}-abcdef012345"  # this test's own process
    for folder in (dead, alive):
        folder.mkdir()
        (folder / REPORT_MARKER).write_text('{"files": {"index.html": ""}}')  # a report writes its marker first
        (folder / PAGE).write_bytes(b"half written")
    commit_folder(tmp_path / REPORT_DIR, {PAGE: b"page"})
    assert not dead.exists() and alive.exists()


def test_the_verdict_comes_first_then_the_warnings_then_the_folded_tally(built):
    build_dir, result = built
    manifest = json.loads((build_dir / "manifest.json").read_text())
    text = (build_dir / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    top = text[:text.index("<nav>")]
    verdict = manifest["verdict"]
    # the first box is the manifest's verdict; the warnings and then the checks' tally, folded, follow it (issue 44)
    assert top.index('id="verdict"') < top.index('id="warnings"') < top.index('id="checks"') < top.index("<table>")
    assert f'data-status="{verdict["status"]}"' in top and html.escape(verdict["headline"]) in top
    for reason in verdict["reasons"]:
        assert top.count(html.escape(reason)) == 1  # said once, not again in the banner
    # every warning of the manifest (the demo's one-arc-per-link misfits) once in the banner, and nowhere else
    for w in (w for w in manifest["warnings"] if w["kind"] == "warning"):
        assert text.count(html.escape(w["text"])) == 1, w["text"]
    for i, entry in enumerate(manifest["outputs"]):  # every exported q's volume is in the summary, traced
        if entry["path"].startswith("meshes/q_") and entry["path"].endswith(".stl"):
            assert f'data-pointer="/outputs/{i}/volume_mm3"' in top, entry["path"]
    assert 'data-pointer="/metrics/feasibility/morph/stretch_max/value"' in top
    assert 'data-pointer="/metrics/fit/max_rho_kappa"' in top


def test_passed_checks_are_folded_away_under_a_tally(built):
    build_dir, result = built
    text = (build_dir / REPORT_DIR / PAGE).read_text(encoding="utf-8")
    folded = text[text.index("<details>"):text.index("</details>", text.index("<details>"))]
    assert folded.count("<tr><td>") == result.checks_passed  # each passed check once, folded
    outputs = json.loads((build_dir / "manifest.json").read_text())["outputs"]
    assert f"<td>file as recorded (sha256)</td><td class=\"num\">{len(outputs)}</td>" in text  # the tally row


#: The demo's page and its files, at most (issue 17: 10 MB).
DEMO_REPORT_BYTES = 10_000_000


def test_the_3d_view_is_offline_and_holds_a_frame_per_q(built):
    import re

    from plotly.offline import get_plotlyjs

    build_dir, result = built
    report_dir = build_dir / REPORT_DIR
    text = (report_dir / PAGE).read_text(encoding="utf-8")
    scripts = re.findall(r"<script[^>]*\bsrc=\"([^\"]+)\"", text)
    assert scripts == [JS_NAME]  # one script file, beside the page
    assert (report_dir / JS_NAME).read_bytes() == get_plotlyjs().encode("utf-8")
    assert "http://" not in text and "https://" not in text  # no address the browser could fetch
    assert f'id="{DIV_ID}"' in text
    names = re.findall(r'"name":"(\d\.\d{3})"', text)
    assert names == [f"{q:.3f}" for q in np.linspace(0.0, 1.0, 21)]
    assert sum(result.files.values()) < DEMO_REPORT_BYTES
    stated = [float(x) for x in re.findall(r"display error(?: at q = 1)? ([0-9.]+) mm", text)]
    assert stated and max(stated) <= DISPLAY_TOLERANCE_MM  # the page states each display error, within tolerance


def test_the_hollow_body_is_cut_through_its_wall_and_chamber(tmp_path):
    """A hollow build's q = 1 cut half way is two closed loops: the outer skin and the chamber."""
    from softdesign.io.surface import read_surface
    from softdesign.report.build_folder import load_build
    from softdesign.report.profile_figures import cross_section

    case = tmp_path / "hollow.yaml"
    text = DEMO_CASE.read_text().replace("../data", str(REPO / "data"))
    # q = 1 alone, the q this test cuts and compares (the demo's three: 4.4 s of CPU to build, this 2.7 s)
    assert "q: [0, 0.5, 1]" in text
    text = text.replace("q: [0, 0.5, 1]", "q: [1]")
    case.write_text(text.replace("formats: [stl]}", "formats: [stl, glb], wall_mm: 1.0, port_mm: 1.5}"))
    build_through(case, tmp_path / "build")
    data = load_build(tmp_path / "build")
    segments = cross_section(data, *read_surface(data.mesh_file(1.0)), 0.5)
    radii = np.linalg.norm(segments.reshape(-1, 2), axis=1)
    mean_rho = float(data.fit.field.evaluate_grid(1.0, np.array([0.5]), np.linspace(0, 2 * np.pi, 96))[0].mean())
    outer, inner = radii[radii > mean_rho - 0.5], radii[radii < mean_rho - 0.5]
    # the wall is 1 mm: the chamber's loop sits 1 mm inside the skin's (to the mesh's chord error, 0.1 mm)
    np.testing.assert_allclose(outer.mean() - inner.mean(), 1.0, rtol=0, atol=0.1)
    result = write_report(tmp_path / "build", FEW_FRAMES)
    assert "profile.png" in result.files
    import trimesh

    glb = trimesh.load(tmp_path / "build" / "meshes" / "q_1.000.glb", force="mesh")
    stl = trimesh.load(tmp_path / "build" / "meshes" / "q_1.000.stl")
    np.testing.assert_allclose(glb.extents * 1000.0, stl.extents, rtol=1e-6, atol=0)  # glTF in metres


def test_a_large_surface_map_draws_the_points_left_on_top_and_says_so(demo, monkeypatch):
    from softdesign.report import fit_figures
    from softdesign.report.build_folder import load_build

    data = load_build(demo[0])
    distances = fit_figures.true_distances(data)
    total = len(data.ingest.vertices)
    assert "The map draws" not in fit_figures.distance_picture(data, distances).caption  # under MAP_POINTS: all
    monkeypatch.setattr(fit_figures, "MAP_POINTS", 1000)  # the demo's 8,455 vertices count as a large surface
    caption = fit_figures.distance_picture(data, distances).caption
    shown = int(caption.split("The map draws ")[1].split(" of ")[0])
    assert f"of the {total} vertices" in caption
    assert 0 < shown < total
