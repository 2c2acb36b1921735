"""Browser helpers for the panel tests: Playwright driving Debian chromium headless, a panel
on the bundled office walk, waiting, and projecting world points to pixels."""

import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.building.floorplan import FloorPlan
from workstation.editor import SurveyEditor
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


@pytest.fixture(autouse=True)
def _close_pages(request):
    """Every page a test opened is closed after it, passed or failed: a page left open keeps
    rendering (software WebGL) and starves the tests after it."""
    yield
    if "browser" in request.fixturenames:
        for ctx in request.getfixturevalue("browser").contexts:
            ctx.close()


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
    t0 = time.time()
    page.on("console", lambda m: print(f"[{time.time() - t0:6.1f} s] console {m.type}: {m.text}"))
    page.on("pageerror", lambda e: print(f"[{time.time() - t0:6.1f} s] page error: {e}"))
    page.on("crash", lambda p: print(f"[{time.time() - t0:6.1f} s] page crashed"))
    local = ("http://127.0.0.1", "ws://127.0.0.1", "data:", "blob:")
    page.route(
        "**/*",
        lambda route: route.continue_() if route.request.url.startswith(local) else route.abort(),
    )
    page.goto(f"http://127.0.0.1:{panel.port}")
    page.get_by_role("button", name="Re-run").wait_for(timeout=30000)
    assert wait_for(lambda: page.evaluate(GL_READY), timeout=30.0), page_state(page)
    return page


def framed(panel, client, timeout: float = 30.0) -> bool:
    """Wait until the tab's camera reports a view over the building (a tab that missed the
    initial camera is framed on its first report, and reports again a moment later). The
    server-side handle takes a new position and look-at at once but its orientation only from
    the tab's next report: both must agree before a point is projected."""

    def over() -> bool:
        cam = client.camera
        if cam.image_height <= 0:
            return False
        if not panel.views_building(cam.position, cam.look_at):
            return False
        d = np.asarray(cam.look_at, float) - np.asarray(cam.position, float)
        return bool(_rotation(cam.wxyz)[:, 2] @ d > 0.999 * np.linalg.norm(d))  # looks along d

    if wait_for(over, timeout=timeout / 2):
        return True
    cam = client.camera  # rare (about 1 full run in 10 here); not understood: said, then Reset view
    print("camera not over the building:", cam.position, cam.look_at, cam.wxyz, cam.image_height)
    print("building centre", panel.centre, "extent", panel.extent, "-> Reset view")
    panel.draw.reset_view(client)
    return wait_for(over, timeout=timeout / 2)


FRAMES = """(n) => new Promise((done) => {
  let k = 0;
  const step = () => (++k >= n ? done(k) : requestAnimationFrame(step));
  requestAnimationFrame(step);
})"""


def frames(page, n: int = 10) -> None:
    """Wait until the page has drawn ``n`` more frames: what the scene needs to settle (a fade,
    a message applied, a hit test rebuilt) counted in the page's own frames — as many on a
    loaded machine as on an idle one — instead of a fixed time."""
    page.evaluate(FRAMES, n)


def wait_for(cond, timeout=10.0):
    end = time.time() + timeout
    while time.time() < end:
        if cond():
            return True
        time.sleep(0.1)
    return False


def _rotation(wxyz) -> np.ndarray:
    """Camera-to-world rotation from viser's quaternion (its third column: where it looks)."""
    w, x, y, z = wxyz
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def on_page(page, cam, p) -> tuple[float, float]:
    """World point → page pixel (CSS), from the client's camera (OpenCV convention, as viser
    reports it). viser reports the canvas in device pixels, which its frame-rate governor scales
    down to 0.75 when rendering is slow (software WebGL under load): the pixel is taken as a
    fraction of that size and placed on the canvas's box on the page."""
    pc = _rotation(cam.wxyz).T @ (np.asarray(p, float) - np.asarray(cam.position, float))
    h, wd = cam.image_height, cam.image_width
    f = (h / 2) / np.tan(cam.fov / 2)
    fu, fv = 0.5 + f * pc[0] / pc[2] / wd, 0.5 + f * pc[1] / pc[2] / h
    box = page.evaluate(CANVAS_BOX)
    return box["x"] + fu * box["width"], box["y"] + fv * box["height"]


GL_READY = (
    "() => { const m = window.__viserMutable; return !!(m && m.canvas && m.canvas.width > 0); }"
)

CANVAS_BOX = """() => {
  const c = window.__viserMutable.canvas;
  const r = c.getBoundingClientRect();
  return {x: r.left, y: r.top, width: r.width, height: r.height};
}"""


def click_until(page, camera, point, cond, tries: int = 5, wait_s: float = 8.0) -> bool:
    """Click the world ``point`` until ``cond()`` holds (a click made while the page is busy can
    be dropped). Escape first closes a dropdown still open over the page. Only for clicks that
    are harmless twice (placing where a landmark now is selects it; a control point's pixel is
    set again). On failure it prints where the clicks landed, the page's state and the camera."""
    for _ in range(tries):
        page.keyboard.press("Escape")
        u, v = on_page(page, camera, point)
        hit = page.evaluate(HIT, [u, v])
        print(f"click at ({u:.0f}, {v:.0f}) px lands on {hit}")
        page.mouse.click(u, v)
        if wait_for(cond, timeout=wait_s):
            return True
    print("page state:", page_state(page), "camera:", camera.position, camera.look_at)
    return False


def drag_until(page, camera, point, by, cond, tries: int = 3, wait_s: float = 8.0) -> bool:
    """Drag from the world ``point`` by ``by`` page pixels until ``cond()`` holds. A drag made
    while software WebGL renders a few frames a second can be missed (the press must land on a
    rendered frame's hit test): each try moves in small steps with time for frames between them,
    and is repeated only while nothing moved (so it never drags twice)."""
    for _ in range(tries):
        u, v = on_page(page, camera, point)
        print(f"drag from ({u:.0f}, {v:.0f}) px, on {page.evaluate(HIT, [u, v])}")
        page.mouse.move(u, v)
        time.sleep(0.3)
        page.mouse.down()
        time.sleep(0.3)
        for k in range(1, 11):
            page.mouse.move(u + by[0] * k / 10, v + by[1] * k / 10)
            time.sleep(0.1)
        page.mouse.up()
        if wait_for(cond, timeout=wait_s):
            return True
    print("page state:", page_state(page), "camera:", camera.position, camera.look_at)
    return False


def page_state(page) -> dict:
    """What the browser says about the page when a test waits in vain (for its message)."""
    page.screenshot(path=f"/tmp/panel_{int(time.time())}.png")
    return page.evaluate(STATE)


STATE = """async () => {
  const c = window.__viserMutable && window.__viserMutable.canvas;
  let frames = 0;
  const t0 = performance.now();
  await new Promise((done) => {
    const tick = () => { frames++; performance.now() - t0 < 1000 ? requestAnimationFrame(tick) : done(); };
    requestAnimationFrame(tick);
  });
  return {visibility: document.visibilityState, focus: document.hasFocus(), frames,
          canvas: c ? [c.width, c.height, c.clientWidth, c.clientHeight] : null};
}"""


def on_canvas(page, camera, point) -> bool:
    """Whether the world ``point`` is on the scene's canvas on the page, not under the control
    panel (or off the page)."""
    u, v = on_page(page, camera, point)
    return page.evaluate(HIT, [u, v]).startswith("CANVAS")


HIT = """([x, y]) => {
  const e = document.elementFromPoint(x, y);
  return e ? `${e.tagName}.${e.className}` : "nothing";
}"""


def _choose(page, label, option):
    el = page.get_by_label(label)
    el.scroll_into_view_if_needed()
    el.click()
    page.get_by_role("option", name=option).click()


def shown_x(page) -> float:
    """The x the tab's landmark fields show (NaN until drawn)."""
    try:
        return float(page.get_by_label("x (m)", exact=True).first.input_value(timeout=1000))
    except Exception:  # noqa: BLE001 - not drawn yet
        return float("nan")


def whole_floor(page, pan, client) -> None:
    """Press "Whole floor" (the plan's control points and drawing span the whole plan)."""
    page.get_by_role("button", name="Whole floor").click()
    assert wait_for(lambda: abs(client.camera.position[2] - 1.1 * pan.extent) < 1.0, timeout=20)
    assert framed(pan, client)
