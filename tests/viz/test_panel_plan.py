"""The floor plan in the panel in a real browser (issues #13, #30): control points place the
plan (and slips are refused or asked), the plan image lies under the walk."""

import shutil

import numpy as np
import pytest

from tests.conftest import REPO
from tests.viz.conftest import (
    _choose,
    click_until,
    framed,
    frames,
    on_page,
    open_page,
    page_state,
    wait_for,
    whole_floor,
)
from workstation.editor import SurveyEditor
from workstation.graph import LandmarkGraph
from workstation.session import load_session

pytestmark = pytest.mark.browser


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
        assert framed(pan, client)
        whole_floor(page, pan, client)  # the panel opens on the walk
        frames(page)
        page.get_by_text("Control points (place the plan)").click()  # open the folder
        _choose(page, "Click on the plan", "control point")
        assert wait_for(lambda: pan.draw.mode.value == "control point")
        frames(page, 30)  # the page hears that clicks now go to the server (click_until retries)
        img = before.image(0.0)
        for x, y in ((100.0, 110.0), (150.0, 60.0)):
            assert click_until(page, client.camera, (x, y, 0.0), lambda: pan.georef.pixel), (
                pan.ed.message,
                pan.draw.mode.value,
            )
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
        assert framed(pan, client)
        whole_floor(page, pan, client)  # the panel opens on the walk

        def shot():
            return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)

        def blue(a):  # the shops' light blue (faded by the opacity slider)
            r, gg, b = a[..., 0], a[..., 1], a[..., 2]
            return (b - r > 15) & (gg - r > 10) & (b > 180)

        for _state, sphere, _label in pan.scene.node_handles.values():
            sphere.visible = False  # a gyro landmark's blue sphere (16 px) is not a shop

        assert wait_for(lambda: blue(shot()).mean() > 0.05, timeout=20), (
            page_state(page),
            client.camera.position,
            client.camera.look_at,
        )
        img = pan.building.image(0)
        alpha = np.asarray(Image.open(img.path).convert("RGBA"))[..., 3]
        rng = np.random.default_rng(0)
        pu, pv = rng.uniform(5, 795, 400), rng.uniform(5, 583, 400)
        xs, ys = img.to_metres(pu, pv)

        def placed():
            """Tapped waypoints on shops, and pixel agreement with the image's transform, on
            one screenshot with the camera of that moment."""
            a, cam = shot(), client.camera
            on_shop = 0
            for x, y in zip(s.ground_truth.x, s.ground_truth.y):
                u, v = on_page(page, cam, (x, y, 0.0))  # a screenshot pixel is a CSS pixel
                u, v = int(round(u)), int(round(v))
                on_shop += int(blue(a[v - 1 : v + 2, u - 1 : u + 2]).all())
            agree = []  # the image is where its transform says: shop or not, pixel by pixel
            for uu, vv, x, y in zip(pu, pv, xs, ys):
                u, v = on_page(page, cam, (x, y, 0.0))  # a screenshot pixel is a CSS pixel
                u, v = int(round(u)), int(round(v))
                if 0 <= v < a.shape[0] and 0 <= u < a.shape[1] - 360:  # not under the GUI
                    agree.append(bool(blue(a[v, u])) == bool(alpha[int(vv), int(uu)] > 0))
            return on_shop, len(agree), float(np.mean(agree)) if agree else 0.0

        last = []

        def settled():  # the view may still be settling when the first frames arrive
            last[:] = placed()
            return last[0] <= 1 and last[1] > 200 and last[2] > 0.85

        assert wait_for(settled, timeout=30), last
        page.close()
    finally:
        pan.stop()


def test_control_point_slips_are_refused_or_asked(tmp_path):
    """Issue #30 item 6: a control point whose true position was never typed (the fields still
    say where the plan puts the pixel: it would pin the plan where it is) is refused; Clear
    drops the points only on a second click, the first says how many would go."""
    from workstation.building import Building
    from workstation.viz.panel import SurveyPanel

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    for name in ("graph.yaml", "building.yaml"):
        shutil.copy(ms / name, tmp_path / name)
    bpath = tmp_path / "building.yaml"
    bpath.write_text(bpath.read_text().replace("floor_image.png", str(ms / "floor_image.png")))
    g = tmp_path / "graph.yaml"
    ed = SurveyEditor(load_session(ms), LandmarkGraph.load(g), graph_path=g, out_dir=tmp_path / "o")
    pan = SurveyPanel(ed, None, port=0, building=Building.load(bpath), building_path=bpath)
    try:
        geo = pan.georef
        geo.pick(100.0, 110.0)
        geo.add(float(geo.x_in.value), float(geo.y_in.value))
        assert not geo.points and ed.message.startswith("refused: type where the point really is")
        geo.add(103.0, 110.0)
        assert len(geo.points) == 1
        geo.clear()
        assert len(geo.points) == 1 and "again to drop all 1 control points" in ed.message
        geo.clear()
        assert not geo.points and ed.message == "1 control points dropped"
    finally:
        pan.stop()
