"""The viser panel in a real browser, several tabs on one panel (issues #18, #51, #55): each
tab edits its own landmark, both edits of one landmark are kept or the second is told why, a
landmark deleted in one tab leaves the others whole, the graph is never corrupted."""

import re
import time

import pytest

from tests.viz.conftest import open_page, shown_x, wait_for
from workstation.graph import LandmarkGraph

pytestmark = pytest.mark.browser


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
            x = round(g0.node(nid).x + 0.01 * (i + 1), 3)
            # select and type as one step, as a browser's events arrive: not in the middle of
            # the forms' refresh after the last Apply (which put the old x back, CI run 69)
            with panel.redraw_lock:
                f.select(nid)
                f.x_in.value = x
            expected[nid] = x
        # the tabs show what was typed before they apply: a click before the value reached the
        # browser sent the field's old value back with it (under load: 'nothing to apply')
        want = sorted([fa.x_in.value, fb.x_in.value])
        # (a bound on the wait, not a speed test: CI failed once at 20 s with another job
        # running on the machine's two cores)
        assert wait_for(lambda w=want: sorted(shown_x(p) for p in (a, b)) == w, timeout=60), (i, want, [shown_x(p) for p in (a, b)], panel.ed.message)
        for page in (a, b):
            page.get_by_role("button", name="Apply to landmark").click()
        assert wait_for(lambda: all(panel.ed.graph.node(n).x == x for n, x in expected.items()),
                        timeout=60), (i, panel.ed.message, {n: (panel.ed.graph.node(n).x, x) for n, x in expected.items()}, fa.selected, fb.selected, fa.x_in.value, fb.x_in.value)  # fmt: skip
    a.get_by_role("button", name="Save graph").click()
    assert wait_for(lambda: panel.ed.unsaved == [])
    saved = LandmarkGraph.load(panel.ed.graph_path)
    for nid, x in expected.items():
        assert saved.node(nid).x == x, nid
    untouched = [n for n in g0.nodes if n.id not in expected]
    assert all(saved.node(n.id).x == n.x and saved.node(n.id).y == n.y for n in untouched)
    a.close()
    b.close()


def test_a_landmark_deleted_in_another_tab_leaves_this_tab_whole(browser, panel):
    """Issue #55 item 7: one tab deleting the landmark another tab showed raised a KeyError in
    that tab's sync_fields, cutting every tab's redraw short."""
    page = open_page(browser, panel)
    assert wait_for(lambda: len(panel.forms) >= 1)
    form = list(panel.forms.values())[-1]
    nid = panel.ed.add_node(3.0, 3.0, panel.floor)
    form.select(nid)
    assert form.selected == nid
    panel.ed.delete_node(nid)  # as another tab would, between this tab's redraws
    form.sync_fields()  # raised KeyError
    assert form.selected is None and form._shown is None
    panel.after_edit()
    assert wait_for(lambda: form.sel_dd.value == "(none)")
    page.close()


def _shows(page, label, value) -> bool:
    """The tab's field shows ``value`` (what the server last sent it has arrived)."""
    try:
        return float(page.get_by_label(label, exact=True).first.input_value()) == float(value)
    except ValueError:
        return False


def _type(page, label, value):
    box = page.get_by_label(label, exact=True).first
    box.fill(str(value))
    box.press("Tab")


def _typed(page, label, value, handle) -> bool:
    """Type ``value`` until the server's field has it: on a loaded machine a page still
    redrawing the field from the server's last update once took that update over the typing
    (3 tries of 10 s)."""
    for _ in range(3):
        _type(page, label, value)
        if wait_for(lambda: handle.value == value, timeout=10):
            return True
    return False


def test_two_tabs_on_one_landmark_keep_both_edits_or_say_why_not(browser, panel):
    """Issue #51: A types x, B types y on the same landmark, both apply — both edits kept (were
    0 of 10: B's form was re-read after A's Apply, or B's stale x undid A's). A field both tabs
    changed is not applied by the second, which is told what the other set (Apply again
    overwrites). Undo takes back the tab's own edit and never another tab's without saying so;
    a new tab opens with its own status line, not another tab's "refused"."""
    a = open_page(browser, panel)
    assert wait_for(lambda: len(panel.forms) == 1)
    b = open_page(browser, panel)
    assert wait_for(lambda: len(panel.forms) == 2)
    fa, fb = list(panel.forms.values())
    n = panel.ed.graph.node("DS0")
    for f in (fa, fb):
        f.select("DS0")
    x, y = round(n.x + 1.5, 3), round(n.y + 2.5, 3)
    assert _typed(a, "x (m)", x, fa.x_in) and _typed(b, "y (m)", y, fb.y_in)
    assert wait_for(lambda: (fa.x_in.value, fb.y_in.value) == (x, y), timeout=30)
    a.get_by_role("button", name="Apply to landmark").click()
    b.get_by_role("button", name="Apply to landmark").click()
    here = lambda: (panel.ed.graph.node("DS0").x, panel.ed.graph.node("DS0").y)  # noqa: E731
    assert wait_for(lambda: here() == (x, y), timeout=30), here()
    # both change x: the second is told, and keeps what it typed to apply again
    assert wait_for(lambda: (fa.x_in.value, fb.x_in.value) == (x, x), timeout=30)
    wait_for(lambda: _shows(a, "x (m)", x) and _shows(b, "x (m)", x), timeout=15)
    assert _typed(a, "x (m)", 30.0, fa.x_in) and _typed(b, "x (m)", 31.0, fb.x_in)
    assert wait_for(lambda: (fa.x_in.value, fb.x_in.value) == (30.0, 31.0), timeout=30)
    a.get_by_role("button", name="Apply to landmark").click()
    assert wait_for(lambda: here()[0] == 30.0, timeout=30)
    b.get_by_role("button", name="Apply to landmark").click()
    b.get_by_text("not applied: DS0's x was set to 30 meanwhile").first.wait_for(timeout=30000)
    assert here() == (30.0, y) and fb.x_in.value == 31.0
    assert not a.get_by_text("not applied").count()  # told to B only
    b.get_by_role("button", name="Apply to landmark").click()
    assert wait_for(lambda: here()[0] == 31.0, timeout=30)
    # A's Undo would take back B's later move of DS0 too: refused, saying why
    a.get_by_role("button", name="Undo").click()
    a.get_by_text("cannot undo — DS0 was changed since").first.wait_for(timeout=30000)
    assert here() == (31.0, y)
    b.get_by_role("button", name="Undo").click()  # B's own last edit
    assert wait_for(lambda: here() == (30.0, y), timeout=30)
    b.get_by_text("undone: moved DS0 to (31.00").first.wait_for(timeout=30000)
    c = open_page(browser, panel)
    c.get_by_text("status: ready").first.wait_for(timeout=30000)
    assert not c.get_by_text("cannot undo").count()
    # A deletes the landmark while B has a move typed: B's Apply says so (it won silently)
    _type(b, "x (m)", 12.0)
    assert wait_for(lambda: fb.x_in.value == 12.0, timeout=30)
    with panel.ed.by(fa.client.client_id):
        panel.ed.delete_node("DS0")
    b.get_by_role("button", name="Apply to landmark").click()
    # (told at the Apply, or, when its form saw the delete first, on its status line)
    b.get_by_text(re.compile("DS0 was deleted|elsewhere: deleted DS0")).first.wait_for(timeout=30000)
    assert "DS0" not in panel.ed.graph.ids  # the move did not bring it back
