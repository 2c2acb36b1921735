"""The panel's survey-plan layer (issue #32) and its zoom-fitted landmarks (issue #30 item 5)."""

import json

import numpy as np

from tests.viz.conftest import open_page, wait_for
from workstation.viz.panel_zoom import CHAR_PX, LINE_PX, metres_per_pixel, thin


def test_thinned_labels_never_overlap_and_all_show_when_zoomed_in():
    for seed in range(3):
        rng = np.random.default_rng(seed)
        xy = rng.uniform(0, 100, (300, 2))
        chars = rng.integers(3, 20, 300)
        mpp = 0.5  # metres per pixel: a building on a laptop screen
        keep = thin(xy, chars, mpp)
        assert keep[0] and 0 < keep.sum() < 300  # the first (the selection) always shows
        k = np.flatnonzero(keep)
        w = chars * CHAR_PX * mpp
        for a in k:
            for b in k[k > a]:
                apart_x = abs(xy[a, 0] - xy[b, 0]) >= (w[a] + w[b]) / 2
                apart_y = abs(xy[a, 1] - xy[b, 1]) >= LINE_PX * mpp
                assert apart_x or apart_y
        assert thin(xy, chars, 1e-4).all()  # zoomed in: every label


def test_metres_per_pixel_of_a_top_down_camera():
    # 100 m up with a 90° field of view spans 200 m over 1000 pixels
    assert abs(metres_per_pixel((0, 0, 100), (0, 0, 0), np.pi / 2, 1000) - 0.2) < 1e-9


def test_spheres_keep_their_size_on_screen(panel):
    z = panel.zoom
    z.mpp = 0.5  # zoomed out: a 0.6-m sphere would be 2.4 px
    z.apply()
    scales = {float(np.max(h[1].scale)) for h in panel.scene.node_handles.values()}
    assert scales == {16 * 0.5 / 1.2}
    z.mpp = 0.01  # zoomed in: never smaller than its size in metres
    z.apply()
    assert {float(np.max(h[1].scale)) for h in panel.scene.node_handles.values()} == {1.0}
    assert all(h[2].visible for h in panel.scene.node_handles.values())


def test_plan_the_walk_and_the_rewalk_in_the_panel(panel, tmp_path):
    r = panel.route
    r.make(rewalk=False)
    g = panel.ed.graph
    walked = {frozenset((leg.frm, leg.to)) for w in r.plan.walks for leg in w.legs}
    level = {frozenset(e) for e in g.undirected_pairs() if not g.edge(*e)["floor_change"]}
    assert level <= walked
    panel.redraw()
    assert r.legs_on(float(panel.floor)) and "walk(s)" in r.note.content
    r.save()
    plan = json.loads((panel.ed.out_dir / "plan.json").read_text())
    assert plan["kind"] == "survey" and plan["walks"]
    r.make(rewalk=True)  # the walk's own thin edges (quality.thin_edges of its kept points)
    assert r.plan.rewalk
    panel.ed.move_node(g.ids[0], g.node(g.ids[0]).x + 1.0, g.node(g.ids[0]).y)
    panel.after_edit()
    assert "planned before the last graph edit" in r.note.content
    r.clear()
    panel.redraw()
    assert r.plan is None and r.note.content == ""


def test_plan_the_walk_button(browser, panel):
    page = open_page(browser, panel)
    page.get_by_text("Survey plan", exact=True).click()
    page.get_by_role("button", name="Plan the walk").click()
    assert wait_for(lambda: panel.route.plan is not None, timeout=30)
    assert wait_for(lambda: "walk(s)" in panel.route.note.content, timeout=30)
    assert "planned the survey walk" in panel.ed.message


def test_undo_of_an_added_landmark_leaves_no_stale_place_in_the_form(browser, panel):
    """Issue #30 item 6: after Undo of an added landmark the form kept its x/y/floor."""
    open_page(browser, panel)
    cid, form = next(iter(panel.forms.items()))
    nid = panel.ed.add_node(123.0, 77.0, panel.floor)
    panel.after_edit(select=nid, client_id=cid)
    assert (form.x_in.value, form.y_in.value) == (123.0, 77.0)
    panel.ed.undo()
    panel.after_edit()
    assert form.selected is None
    assert (form.x_in.value, form.y_in.value) != (123.0, 77.0)
    assert form.floor_in.value == panel.floor
