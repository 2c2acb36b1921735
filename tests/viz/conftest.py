"""Browser helpers for the panel tests: Playwright driving Debian chromium headless, a panel
on the bundled office walk, waiting, and projecting world points to pixels."""

import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.editor import SurveyEditor
from workstation.floorplan import FloorPlan
from workstation.graph import LandmarkGraph
from workstation.session import load_session

WALK = REPO / "sample_sessions" / "office2f" / "normal"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]


@pytest.fixture(scope="module")
def browser():
    sync_api = pytest.importorskip("playwright.sync_api")
    if not Path(CHROMIUM).exists():
        pytest.skip("Debian chromium is not installed")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=ARGS)
        yield b
        b.close()


@pytest.fixture
def panel(tmp_path):
    from workstation.viz.panel import SurveyPanel

    g = tmp_path / "graph.yaml"
    shutil.copy(WALK / "graph.yaml", g)
    ed = SurveyEditor(
        load_session(WALK), LandmarkGraph.load(g), graph_path=g, out_dir=tmp_path / "out"
    )
    pan = SurveyPanel(ed, FloorPlan.load(WALK / "floorplan.yaml"), port=0)
    yield pan
    pan.stop()


def open_page(browser, panel):
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    local = ("http://127.0.0.1", "ws://127.0.0.1", "data:", "blob:")
    page.route(
        "**/*",
        lambda route: route.continue_() if route.request.url.startswith(local) else route.abort(),
    )
    page.goto(f"http://127.0.0.1:{panel.port}")
    page.get_by_role("button", name="Re-run").wait_for(timeout=30000)
    return page


def wait_for(cond, timeout=10.0):
    end = time.time() + timeout
    while time.time() < end:
        if cond():
            return True
        time.sleep(0.1)
    return False


def _project(cam, p):
    """World point → pixel, from the client's camera (OpenCV convention, as viser reports it)."""
    w, x, y, z = cam.wxyz
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    pc = r.T @ (np.asarray(p, float) - np.asarray(cam.position, float))
    h = cam.image_height
    f = (h / 2) / np.tan(cam.fov / 2)
    return cam.image_width / 2 + f * pc[0] / pc[2], h / 2 + f * pc[1] / pc[2]


def click_until(page, camera, point, cond, tries: int = 5, wait_s: float = 8.0) -> bool:
    """Click the world ``point`` until ``cond()`` holds: the browser learns that scene clicks
    go to the server a moment after the mode is chosen, later under load, and drops a click made
    before that (a clean CI machine once dropped three in 24 s). Escape first closes a dropdown
    still open over the page. Only for clicks that are harmless twice (placing where a landmark
    now is selects it; a control point's pixel is set again)."""
    for _ in range(tries):
        page.keyboard.press("Escape")
        page.mouse.click(*_project(camera, point))
        if wait_for(cond, timeout=wait_s):
            return True
    return False


def _choose(page, label, option):
    el = page.get_by_label(label)
    el.scroll_into_view_if_needed()
    el.click()
    page.get_by_role("option", name=option).click()
