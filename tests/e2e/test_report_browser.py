"""The demo's report page in headless Chromium: offline, no console error, the 3D view drawn, the q slider moving it.

Debian's ``chromium`` (``.ci/run`` installs it with apt-get when it is missing)
is driven by playwright with ``executable_path``: playwright downloads no browser.
WebGL runs on Chromium's software renderer (SwiftShader).  The page is opened
from its folder (file://), the slider's grip is dragged from q = 1 (where the
page opens) to q = 0 with the mouse, and the 3D view is captured at both ends.
The screenshots are kept as test artifacts in :data:`ARTIFACTS` (under build/,
which git ignores).  The tests skip, saying why, only when no browser can run.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np
import pytest
from PIL import Image

from softdesign.pipeline.api import build_through
from softdesign.report.interactive import DIV_ID
from softdesign.report.writer import PAGE, REPORT_DIR, write_report
from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow

ARTIFACTS = REPO / "build" / "test-artifacts" / "browser"
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")
#: Chromium's flags: root needs --no-sandbox; WebGL on the CPU (no GPU in CI) needs SwiftShader allowed.
CHROMIUM_ARGS = ["--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader"]
#: The page parses ~2 MB of figure data on a busy CI machine: allow a minute for the plot to exist.
LOAD_TIMEOUT_MS = 120_000
#: After the slider moves, plotly redraws the frame; let WebGL finish before the capture.
SETTLE_MS = 2_000
#: A pixel is coloured (a link of the actuator, not the grey axes, white background or pale vessel) when its
#: channels spread by at least this much (the demo's four link colours spread 65 to 255).
COLOURED_SPREAD = 50
#: The drawn actuator covers at least this fraction of the 3D canvas (measured 0.9 % at q = 1 and 1.1 % at q = 0
#: on the 1240 x 601 canvas; axes, background and vessel alone give 0).
DRAWN_FRACTION = 0.002
#: Two captures differ when at least this fraction of pixels changes by more than :data:`PIXEL_STEP` levels in a
#: channel (measured 1.5 % between q = 1 and q = 0; the same frame captured twice gives 0).
CHANGED_FRACTION = 0.005
PIXEL_STEP = 10


def chromium() -> str:
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    pytest.skip(f"no Chromium on PATH ({', '.join(CHROMIUM_NAMES)}): apt-get install chromium (.ci/run does)")


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """The demo's page opened, its messages and requests recorded, captured at q = 1 and after the drag to q = 0."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (make install)")
    executable = chromium()
    build_dir = tmp_path_factory.mktemp("browser") / "build"
    build_through(REPO / "configs" / "demo.yaml", build_dir)
    write_report(build_dir)
    report_dir = (build_dir / REPORT_DIR).resolve()
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    record: dict = {"report_dir": report_dir, "messages": [], "requests": []}
    with sync_api.sync_playwright() as playwright:
        try:
            browser = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        except Exception as err:  # playwright's Error: the browser cannot start here
            pytest.skip(f"{executable} cannot start headless: {err}")
        page = browser.new_page(viewport={"width": 1280, "height": 1000})
        page.on("console", lambda m: record["messages"].append((m.type, m.text)))
        page.on("pageerror", lambda e: record["messages"].append(("pageerror", str(e))))
        page.on("request", lambda r: record["requests"].append(r.url))
        page.goto((report_dir / PAGE).as_uri())
        page.wait_for_function(f"document.getElementById('{DIV_ID}')?._fullLayout?.sliders !== undefined",
                               timeout=LOAD_TIMEOUT_MS)
        view = page.locator(f"#{DIV_ID}")
        view.scroll_into_view_if_needed()
        page.wait_for_timeout(SETTLE_MS)
        record["q1"] = capture(page, "demo_q1")
        grip = page.locator(f"#{DIV_ID} .slider-grip-rect").bounding_box()
        rail = page.locator(f"#{DIV_ID} .slider-rail-rect").bounding_box()
        y = grip["y"] + grip["height"] / 2
        page.mouse.move(grip["x"] + grip["width"] / 2, y)
        page.mouse.down()
        page.mouse.move(rail["x"] + 1, y, steps=10)
        page.mouse.up()
        # the slider queues a frame per step passed: wait until plotly has drawn them all, then let WebGL settle
        page.wait_for_function(f"document.getElementById('{DIV_ID}')._transitionData._frameQueue.length === 0",
                               timeout=LOAD_TIMEOUT_MS)
        page.wait_for_timeout(SETTLE_MS)
        record["active"] = page.evaluate(f"document.getElementById('{DIV_ID}')._fullLayout.sliders[0].active")
        record["q0"] = capture(page, "demo_q0")
        browser.close()
    return record


def capture(page, name: str) -> np.ndarray:
    """The whole 3D view saved as ``ARTIFACTS/<name>.png``; returns the WebGL canvas's pixels (RGB)."""
    page.locator(f"#{DIV_ID}").screenshot(path=str(ARTIFACTS / f"{name}.png"))
    canvas = ARTIFACTS / f"{name}_canvas.png"
    page.locator(f"#{DIV_ID} canvas").first.screenshot(path=str(canvas))
    return np.asarray(Image.open(canvas).convert("RGB"), dtype=np.int16)


def coloured_fraction(pixels: np.ndarray) -> float:
    return float(np.mean(pixels.max(axis=2) - pixels.min(axis=2) >= COLOURED_SPREAD))


def test_no_console_error_and_no_request_outside_the_page_folder(session):
    errors = [m for m in session["messages"] if m[0] in ("error", "pageerror")]
    assert errors == []
    assert session["requests"]  # the page itself at least
    for url in session["requests"]:
        parsed = urlparse(url)
        assert parsed.scheme == "file", url  # no http(s), ws or other network address
        assert Path(unquote(parsed.path)).resolve().parent == session["report_dir"], url


def test_the_3d_view_draws_the_actuator(session):
    assert coloured_fraction(session["q1"]) > DRAWN_FRACTION
    assert coloured_fraction(session["q0"]) > DRAWN_FRACTION


def test_dragging_the_slider_from_q_1_to_q_0_changes_the_drawing(session):
    assert session["active"] == 0  # the slider is at its first step, q = 0
    before, after = session["q1"], session["q0"]
    assert before.shape == after.shape
    changed = np.abs(before - after).max(axis=2) > PIXEL_STEP
    assert float(changed.mean()) > CHANGED_FRACTION
