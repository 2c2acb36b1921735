"""The panel's survey-plan layer (issue #32) and its zoom-fitted landmarks (issue #30 item 5)."""

import json

import numpy as np

from tests.viz.conftest import open_page, wait_for
from workstation.viz.panel_zoom import CHAR_PX, LINE_PX, metres_per_pixel, stack, thin


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


def test_stacked_start_hints_never_overlap_and_stay_by_their_landmarks():
    """Issue #50 item 8: an ambiguous start's candidates a few metres apart printed their
    labels on top of each other. Stacked (anchored bottom-right at the landmark), no two boxes
    overlap, the first stays put, each stays over its landmark's x and at most a line per label
    before it above it; the landmark labels under them are thinned away (``fixed``)."""
    for seed in range(4):
        rng = np.random.default_rng(seed)
        n, mpp = 7, 0.3
        xy = rng.uniform(0, 8, (n, 2))  # seven candidates within 8 m: all on one spot at 0.3 m/px
        chars = rng.integers(18, 32, n)
        y = stack(xy, chars, mpp)
        w, h = chars * CHAR_PX * mpp, LINE_PX * mpp
        assert y[0] == xy[0, 1] and np.all(y >= xy[:, 1] - 1e-9)
        assert np.all(y - xy[:, 1] <= h * np.arange(n) + 1e-9 + (xy[:, 1].max() - xy[:, 1]))
        for a in range(n):
            for b in range(a + 1, n):
                apart_x = xy[a, 0] - w[a] >= xy[b, 0] or xy[b, 0] - w[b] >= xy[a, 0]
                assert apart_x or abs(y[a] - y[b]) >= h - 1e-9, (seed, a, b)
        boxes = np.column_stack([xy[:, 0] - w / 2, y + h / 2])
        under = np.array([[x - 1.0, yy + h / 2] for x, yy in zip(xy[:, 0], y)])  # landmark labels
        keep = thin(np.vstack([boxes, under]), np.concatenate([chars, np.full(n, 10)]), mpp, n)
        assert keep[:n].all() and not keep[n:].any()


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
