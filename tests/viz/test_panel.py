"""The viser panel in a real browser: Playwright driving Debian chromium headless."""

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

pytestmark = pytest.mark.browser
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


def test_panel_loads_with_the_run_summary(browser, panel):
    page = open_page(browser, panel)
    assert page.get_by_text("Landmarks matched").is_visible()
    assert page.get_by_role("button", name="Save graph").is_visible()
    page.close()


def test_slider_change_reruns(browser, panel):
    page = open_page(browser, panel)
    page.get_by_text("Parameters", exact=True).click()
    thumb = page.locator('[role="slider"][aria-valuemax="250"][aria-valuenow="15"]')
    thumb.wait_for()

    def trusted():  # on segments belief trusts (gap fill and landmark stops aside)
        m = panel.ed.summary()
        return (
            m["reference_points"]
            - m["reference_points_gap_fill"]
            - m["reference_points_at_landmarks"]
        )

    before = trusted()
    thumb.focus()
    page.keyboard.press("End")  # belief threshold to its maximum
    assert wait_for(lambda: panel.ed.params.belief.threshold == 250.0)
    assert wait_for(lambda: trusted() < before / 2)
    assert before > 0
    page.close()


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


def test_dragging_a_node_moves_it(browser, panel):
    page = open_page(browser, panel)
    time.sleep(2.0)  # the scene fades in
    client = next(iter(panel.server.get_clients().values()))
    assert wait_for(lambda: client.camera.image_height > 0)
    n = panel.ed.graph.node("NE0")
    u, v = _project(client.camera, (n.x, n.y, 0.3))
    page.mouse.move(u, v)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(u - 6 * k, v + 3 * k)
        time.sleep(0.05)
    page.mouse.up()
    assert wait_for(lambda: panel.ed.graph.node("NE0").x < n.x - 1.0), (u, v)
    assert wait_for(lambda: panel.ed.graph.node("NE0").y != n.y)
    assert panel.ed.history  # an undoable edit
    page.close()


def test_save_writes_yaml_and_keeps_a_backup(browser, panel):
    original = panel.ed.graph_path.read_text()
    panel.ed.move_node("DS0", 41.5, 10.0)
    page = open_page(browser, panel)
    page.get_by_role("button", name="Save graph").click()
    bak = panel.ed.graph_path.with_name("graph.yaml.bak")
    assert wait_for(bak.exists)
    assert bak.read_text() == original
    assert LandmarkGraph.load(panel.ed.graph_path).node("DS0").x == 41.5
    page.get_by_text("previous kept as graph.yaml.bak").first.wait_for(timeout=10000)
    page.close()


def test_two_tabs_do_not_corrupt_the_graph(browser, panel):
    a, b = open_page(browser, panel), open_page(browser, panel)
    n0 = len(panel.ed.graph.nodes)
    for _ in range(3):
        a.get_by_role("button", name="Add landmark").click()
        b.get_by_role("button", name="Add landmark").click()
        time.sleep(0.3)
    assert wait_for(lambda: len(panel.ed.graph.nodes) == n0 + 6, timeout=30), (
        len(panel.ed.graph.nodes) - n0
    )
    a.get_by_role("button", name="Save graph").click()
    assert wait_for(lambda: len(LandmarkGraph.load(panel.ed.graph_path).nodes) == n0 + 6)
    ids = LandmarkGraph.load(panel.ed.graph_path).ids
    assert len(ids) == len(set(ids))
    a.close()
    b.close()


def test_refused_edit_is_explained_in_the_panel(browser, panel):
    page = open_page(browser, panel)
    panel.select("SW0")
    page.get_by_role("button", name="Connect", exact=True).click()  # SW0 to itself
    assert wait_for(lambda: "refused" in panel.ed.message)
    page.get_by_text("refused", exact=False).first.wait_for(timeout=30000)
    page.close()


def test_delete_undo_redo_keys(browser, panel):
    """Issue #13: Delete removes the selected landmark, Ctrl+Z brings it back, Ctrl+Y removes it
    again; Backspace typed in a text field edits the field, not the graph."""
    page = open_page(browser, panel)
    panel.select("SW0")
    assert wait_for(lambda: panel.selected == "SW0")
    time.sleep(0.5)
    page.keyboard.press("Delete")
    assert wait_for(lambda: "SW0" not in panel.ed.graph.ids, timeout=30)
    page.keyboard.press("Control+z")
    assert wait_for(lambda: "SW0" in panel.ed.graph.ids, timeout=30)
    page.keyboard.press("Control+y")
    assert wait_for(lambda: "SW0" not in panel.ed.graph.ids, timeout=30)
    page.keyboard.press("Control+z")
    assert wait_for(lambda: "SW0" in panel.ed.graph.ids, timeout=30)
    n = len(panel.ed.graph.nodes)
    panel.select("SW0")
    field = page.get_by_role("textbox").first  # a text field of the panel
    field.scroll_into_view_if_needed()
    field.click()
    field.press("End")
    field.press("Backspace")
    time.sleep(1.5)
    assert len(panel.ed.graph.nodes) == n and "SW0" in panel.ed.graph.ids
    page.close()


def test_the_view_stays_top_down(browser, panel):
    """Issue #13: an orbit drag does not tilt the plan while "Keep the view top-down" is on (the
    default); with it off the same drag tilts the view."""
    page = open_page(browser, panel)
    time.sleep(2.0)
    client = next(iter(panel.server.get_clients().values()))
    assert wait_for(lambda: client.camera.image_height > 0)

    def tilt_deg() -> float:
        d = np.asarray(client.camera.look_at, float) - np.asarray(client.camera.position, float)
        return float(np.degrees(np.arccos(np.clip(-d[2] / np.linalg.norm(d), -1, 1))))

    def drag() -> None:
        page.mouse.move(150, 800)
        page.mouse.down()
        for k in range(1, 16):
            page.mouse.move(150 + 4 * k, 800 - 12 * k)
            time.sleep(0.05)
        page.mouse.up()

    panel.draw.reset_view(client)
    assert wait_for(lambda: tilt_deg() < 1.0), tilt_deg()
    drag()
    time.sleep(1.0)
    assert wait_for(lambda: tilt_deg() < 1.5), tilt_deg()
    panel.draw.top_down.value = False
    drag()
    assert wait_for(lambda: tilt_deg() > 5.0), tilt_deg()
    page.close()


def test_control_points_place_the_plan(browser, tmp_path):
    """Issue #13: control points set in the panel — two features of the Microsoft plan clicked,
    their true positions typed (here: 3 m further east than the image now says) — move the image
    by 3 m, and the building file is saved with the new placement (the old one as .bak)."""
    from workstation.building import Building
    from workstation.viz.panel import SurveyPanel

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    for name in ("graph.yaml", "building.yaml"):
        shutil.copy(ms / name, tmp_path / name)
    text = (
        (tmp_path / "building.yaml")
        .read_text()
        .replace("floor_image.png", str(ms / "floor_image.png"))
    )
    (tmp_path / "building.yaml").write_text(text)
    g, bpath = tmp_path / "graph.yaml", tmp_path / "building.yaml"
    ed = SurveyEditor(load_session(ms), LandmarkGraph.load(g), graph_path=g, out_dir=tmp_path / "o")
    before = Building.load(bpath)
    pan = SurveyPanel(ed, None, port=0, building=before, building_path=bpath)
    try:
        page = open_page(browser, pan)
        client = next(iter(pan.server.get_clients().values()))
        assert wait_for(lambda: client.camera.image_height > 0)
        time.sleep(1.5)
        page.get_by_text("Control points (place the plan)").click()  # open the folder
        _choose(page, "Click on the plan", "control point")
        assert wait_for(lambda: pan.draw.mode.value == "control point")
        time.sleep(2.0)
        img = before.image(0.0)
        for x, y in ((100.0, 110.0), (150.0, 60.0)):
            page.mouse.click(*_project(client.camera, (x, y, 0.0)))
            assert wait_for(lambda: pan.georef.pixel is not None, timeout=30)
            u, v = pan.georef.pixel
            xi, yi = img.to_metres(u, v)  # where the image now puts the clicked pixel
            assert np.hypot(xi - x, yi - y) < 0.5
            pan.georef.x_in.value, pan.georef.y_in.value = float(xi) + 3.0, float(yi)
            page.get_by_role("button", name="Add control point").click()
            assert wait_for(lambda: pan.georef.pixel is None, timeout=30)
        page.get_by_role("button", name="Fit and save building").click()
        assert wait_for(lambda: bpath.with_name("building.yaml.bak").exists(), timeout=30)
        after = Building.load(bpath).image(0.0)
        for u, v in ((0.0, 0.0), (500.0, 300.0)):
            (x0, y0), (x1, y1) = img.to_metres(u, v), after.to_metres(u, v)
            assert abs(x1 - x0 - 3.0) < 0.05 and abs(y1 - y0) < 0.05, ((x0, y0), (x1, y1))
        page.get_by_text("plan placed from 2 control points", exact=False).first.wait_for(
            timeout=30000
        )
        page.close()
    finally:
        pan.stop()


def test_edit_command_serves_on_loopback(tmp_path):
    import subprocess
    import sys
    import urllib.request

    from workstation.viz.rerun_log import free_port

    g = tmp_path / "graph.yaml"
    shutil.copy(WALK / "graph.yaml", g)
    port = free_port()
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "workstation",
            "edit",
            str(WALK),
            "--graph",
            str(g),
            "--plan",
            str(WALK / "floorplan.yaml"),
            "--no-viewer",
            "--port",
            str(port),
            "--out",
            str(tmp_path / "out"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        line = ""
        end = time.time() + 60
        while time.time() < end and "survey panel:" not in line:
            line = proc.stdout.readline()
        assert f"http://127.0.0.1:{port}" in line
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10) as r:
            assert r.status == 200
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_plan_image_lies_under_the_walk(browser, tmp_path):
    """The Microsoft walk with its building file: the floor image is drawn, and the walk's
    tapped waypoints, projected with the browser's camera, fall on its corridors (not on shops,
    which the image paints light blue)."""
    import io

    from PIL import Image

    from workstation.building import Building
    from workstation.viz.panel import SurveyPanel

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    g = tmp_path / "graph.yaml"
    shutil.copy(ms / "graph.yaml", g)
    s = load_session(ms)
    ed = SurveyEditor(s, LandmarkGraph.load(g), graph_path=g, out_dir=tmp_path / "out")
    pan = SurveyPanel(ed, None, port=0, building=Building.load(ms / "building.yaml"))
    try:
        page = open_page(browser, pan)
        client = next(iter(pan.server.get_clients().values()))
        assert wait_for(lambda: client.camera.image_height > 0)

        def shot():
            return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)

        def blue(a):  # the shops' light blue (faded by the opacity slider)
            r, gg, b = a[..., 0], a[..., 1], a[..., 2]
            return (b - r > 15) & (gg - r > 10) & (b > 180)

        assert wait_for(lambda: blue(shot()).mean() > 0.05, timeout=20)
        a = shot()
        sx = a.shape[1] / client.camera.image_width
        on_shop = 0
        for x, y in zip(s.ground_truth.x, s.ground_truth.y):
            u, v = _project(client.camera, (x, y, 0.0))
            u, v = int(round(u * sx)), int(round(v * sx))
            on_shop += int(blue(a[v - 1 : v + 2, u - 1 : u + 2]).all())
        assert on_shop <= 1, on_shop
        # and the image is where its transform says: shop or not, pixel by pixel
        img = pan.building.image(0)
        alpha = np.asarray(Image.open(img.path).convert("RGBA"))[..., 3]
        rng = np.random.default_rng(0)
        pu, pv = rng.uniform(5, 795, 400), rng.uniform(5, 583, 400)
        xs, ys = img.to_metres(pu, pv)
        agree = []
        for uu, vv, x, y in zip(pu, pv, xs, ys):
            u, v = _project(client.camera, (x, y, 0.0))
            u, v = int(round(u * sx)), int(round(v * sx))
            if 0 <= v < a.shape[0] and 0 <= u < a.shape[1] - 360:  # not under the GUI
                agree.append(bool(blue(a[v, u])) == bool(alpha[int(vv), int(uu)] > 0))
        assert len(agree) > 200 and np.mean(agree) > 0.85, (len(agree), np.mean(agree))
        page.close()
    finally:
        pan.stop()


def _choose(page, label, option):
    el = page.get_by_label(label)
    el.scroll_into_view_if_needed()
    el.click()
    page.get_by_role("option", name=option).click()


def test_draw_a_graph_on_the_plan_by_clicking(browser, tmp_path):
    """Issue #13: a new graph on the Microsoft floor image — three landmarks placed by clicking
    on the plan, connected by clicking, saved; the saved coordinates are within 0.5 m of the
    plan positions clicked and `run` uses them."""
    from workstation.building import Building
    from workstation.cli import main
    from workstation.viz.panel import SurveyPanel

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    g = tmp_path / "graph.yaml"
    ed = SurveyEditor(
        load_session(ms), LandmarkGraph((), (), None, source=str(g)), graph_path=g,
        out_dir=tmp_path / "out",
    )  # fmt: skip
    pan = SurveyPanel(ed, None, port=0, building=Building.load(ms / "building.yaml"))
    try:
        page = open_page(browser, pan)
        client = next(iter(pan.server.get_clients().values()))
        assert wait_for(lambda: client.camera.image_height > 0)
        time.sleep(1.5)
        targets = [(100.0, 110.0), (120.0, 110.0), (120.0, 95.0)]
        _choose(page, "Click on the plan", "place landmarks")
        assert wait_for(lambda: pan.draw.mode.value == "place landmarks")
        time.sleep(2.0)  # the browser hears that clicks now go to the server (slow under load)
        for x, y in targets:
            n = len(pan.ed.graph.nodes)
            page.mouse.click(*_project(client.camera, (x, y, 0.0)))
            assert wait_for(lambda n=n: len(pan.ed.graph.nodes) == n + 1)
        page.mouse.click(*_project(client.camera, (100.3, 110.2, 0.0)))  # snaps, adds nothing
        time.sleep(0.5)
        assert len(pan.ed.graph.nodes) == 3
        _choose(page, "Click on the plan", "connect landmarks")
        assert wait_for(lambda: pan.draw.mode.value == "connect landmarks")
        time.sleep(2.0)  # the browser hears that clicks now go to the server (slow under load)
        for a, b in ((0, 1), (1, 2)):
            for i in (a, b):
                page.mouse.click(*_project(client.camera, (*targets[i], 0.0)))
                time.sleep(0.8)
        assert wait_for(lambda: len(pan.ed.graph.edges) == 4, timeout=30.0)
        page.get_by_role("button", name="Save graph").click()
        assert wait_for(g.exists)
        saved = LandmarkGraph.load(g)
        for (x, y), n in zip(targets, sorted(saved.nodes, key=lambda n: n.id)):
            assert np.hypot(n.x - x, n.y - y) < 0.5, (n, x, y)
        assert saved.node("N1").rules == frozenset({"gyro"})
        page.close()
    finally:
        pan.stop()
    out = tmp_path / "run"
    assert main(["run", str(ms), "--graph", str(g), "--out", str(out), "--start", "N1"]) == 0
    import json

    assert json.loads((out / "summary.json").read_text())["start_node"] == "N1"


def test_unsaved_marker_segments_and_save_notification(browser, panel):
    """An edit shows "unsaved graph" in the status; Save clears it and a notification says so
    where the surveyor looks; the segments and their belief are listed (issue #14)."""
    panel.ed.move_node("DS0", 41.0, 10.0)
    panel.after_edit()
    page = open_page(browser, panel)
    page.get_by_text("unsaved graph").wait_for(timeout=5000)
    page.get_by_text("Segments and belief").click()
    page.get_by_text("from → to").wait_for(timeout=5000)
    page.get_by_role("button", name="Save graph").click()
    page.get_by_text("Done", exact=True).wait_for(timeout=10000)
    assert wait_for(lambda: not page.get_by_text("unsaved graph").count())
    page.close()


def test_coverage_toggle_and_ap_selector(browser, panel):
    """Issue #15: the quality folder draws the coverage map, then one AP's heatmap, on the floor
    on view (what each shows is said beside it)."""
    page = open_page(browser, panel)
    page.get_by_text("Radio-map quality", exact=True).click()
    page.get_by_text("Coverage", exact=True).click()
    page.get_by_text("within 3 m of a kept reference point").wait_for(timeout=15000)
    assert panel.quality.coverage.value and panel.quality.ap.value == "none"
    aps = panel.quality.ap.options
    assert len(aps) > 3  # none + the strongest APs of the map
    panel.quality.ap.value = aps[1]  # as the dropdown does (its menu is a portal)
    page.get_by_text(f"RSS of {aps[1]}").wait_for(timeout=15000)
    assert not panel.quality.coverage.value  # one layer at a time
    page.screenshot(path=str(panel.ed.out_dir.parent / "quality.png"))
    page.close()


def test_two_tabs_each_edit_their_own_landmark(browser, panel):
    """Issue #18: two tabs, 50 interleaved edits each — each selects its landmark and types a
    position, then both apply; every accepted edit lands on the landmark its tab showed and is
    in the saved graph (with one shared selection, a tab's Apply hit the other tab's landmark)."""
    a, b = open_page(browser, panel), open_page(browser, panel)
    assert wait_for(lambda: len(panel.forms) == 2)
    fa, fb = list(panel.forms.values())
    g0 = panel.ed.graph
    mine = {fa: [n.id for n in g0.nodes if n.floor == 0][:5],
            fb: [n.id for n in g0.nodes if n.floor == 1][:5]}  # fmt: skip
    expected = {}
    for i in range(50):
        for f in (fa, fb):
            nid = mine[f][i % 5]
            f.select(nid)
            x = round(g0.node(nid).x + 0.01 * (i + 1), 3)
            f.x_in.value = x
            expected[nid] = x
        for page in (a, b):
            page.get_by_role("button", name="Apply to landmark").click()
        assert wait_for(lambda: all(panel.ed.graph.node(n).x == x for n, x in expected.items()),
                        timeout=20), (i, panel.ed.message, {n: (panel.ed.graph.node(n).x, x) for n, x in expected.items()}, fa.selected, fb.selected, fa.x_in.value, fb.x_in.value)  # fmt: skip
    a.get_by_role("button", name="Save graph").click()
    assert wait_for(lambda: panel.ed.unsaved == [])
    saved = LandmarkGraph.load(panel.ed.graph_path)
    for nid, x in expected.items():
        assert saved.node(nid).x == x, nid
    untouched = [n for n in g0.nodes if n.id not in expected]
    assert all(saved.node(n.id).x == n.x and saved.node(n.id).y == n.y for n in untouched)
    a.close()
    b.close()
