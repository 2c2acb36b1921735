"""Two tabs on one editor (issues #50 item 7, #51): each tab's Undo takes back its own edits and
keeps the others'; what a tab is told is its own; an edit whose landmark was changed since is
not taken back without a word. Without a browser: the editor as the panel's tabs drive it."""

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.editor import SurveyEditor
from workstation.editor.history import Conflict, carry
from workstation.graph import LandmarkGraph
from workstation.session import load_session

WALK = REPO / "sample_sessions" / "office2f" / "normal"
A, B = 101, 202  # two tabs' ids


@pytest.fixture(scope="module")
def session():
    return load_session(WALK)


@pytest.fixture
def editor(tmp_path, session):
    g = tmp_path / "graph.yaml"
    g.write_text((WALK / "graph.yaml").read_text())
    return SurveyEditor(session, LandmarkGraph.load(g), graph_path=g, out_dir=tmp_path / "out")


def test_a_tabs_undo_takes_back_its_own_edit_and_keeps_the_others(editor):
    g0 = editor.graph
    with editor.by(A):
        nid = editor.add_node(5.0, 5.0, 0.0)
    with editor.by(B):
        assert editor.move_node("DS0", 41.0, 11.0)
        assert editor.undo() and editor.graph.node("DS0") == g0.node("DS0")  # B's own, last
        assert nid in editor.graph.ids  # A's landmark stays (one shared history took it)
        assert editor.move_node("DS0", 42.0, 12.0)
    with editor.by(A):
        assert editor.undo()
        assert "added " + nid in editor.message and "1 later edit(s) of other tabs kept" in editor.message
        assert nid not in editor.graph.ids and editor.graph.node("DS0").x == 42.0
        assert not editor.undo() and editor.message == "nothing of this tab to undo"
        assert editor.graph.node("DS0").x == 42.0
        assert editor.redo() and nid in editor.graph.ids and editor.graph.node("DS0").x == 42.0
    with editor.by(B):
        assert editor.undo() and editor.graph.node("DS0") == g0.node("DS0")
    with editor.by(A):
        assert editor.undo()
    assert editor.graph == g0 and editor.unsaved == []


def test_an_edit_changed_since_by_another_tab_is_not_taken_back_silently(editor):
    with editor.by(A):
        assert editor.move_node("DS0", 41.0, 11.0)
    with editor.by(B):
        assert editor.move_node("DS0", 43.0, 13.0)
    with editor.by(A):
        assert not editor.undo()
        assert "refused: cannot undo — DS0 was changed since" in editor.message
    assert editor.graph.node("DS0").x == 43.0  # nothing changed
    with editor.by(B):
        assert editor.undo() and editor.graph.node("DS0").x == 41.0
    with editor.by(A):  # now it can
        assert editor.undo() and editor.graph.node("DS0").x != 41.0


def test_undo_of_a_delete_brings_back_the_landmark_and_its_edges(editor):
    g0 = editor.graph
    edges = [e for e in g0.edges if "DS0" in e]
    assert edges
    with editor.by(A):
        assert editor.delete_node("DS0")
    with editor.by(B):
        nid = editor.add_node(3.0, 3.0, 0.0)
    with editor.by(A):
        assert editor.undo()
    assert editor.graph.node("DS0") == g0.node("DS0")
    assert set(edges) <= set(editor.graph.edges) and nid in editor.graph.ids


def test_each_tab_hears_what_it_did_and_what_changed_elsewhere(editor):
    with editor.by(A):
        assert not editor.connect("SW0", "SW0")
        refused = editor.message
    assert refused.startswith("refused")
    since = editor.edits.tick()  # a tab opening now
    assert editor.edits.said_to(B, since) == "ready"  # not A's "refused"
    assert editor.edits.said_to(A, 0) == refused
    with editor.by(A):
        editor.move_node("DS0", 41.0, 11.0)
    told_b = editor.edits.said_to(B, since)
    assert told_b == "ready · meanwhile, elsewhere: moved DS0 to (41.00, 11.00)"
    assert "meanwhile" not in editor.edits.said_to(A, 0)
    editor.message = "saved graph.yaml"  # said to every tab (no tab acting)
    assert editor.edits.said_to(B, since) == "saved graph.yaml"


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_undoing_one_tabs_edits_leaves_exactly_the_others(editor, seed):
    """Two tabs edit disjoint landmarks in a random order (moves, floors, renames, adds,
    deletes, connections); undoing all of A's edits leaves the graph B's edits alone make."""
    rng = np.random.default_rng(seed)
    g0 = editor.graph
    ids = [n.id for n in g0.nodes if n.floor == 0]
    mine = {A: ids[: len(ids) // 2], B: ids[len(ids) // 2 :]}
    only_b = g0
    for k in range(24):
        tab = (A, B)[rng.integers(2)]
        pool = [i for i in mine[tab] if i in editor.graph.ids]
        nid = pool[rng.integers(len(pool))]
        kind = rng.integers(4)
        with editor.by(tab):
            if kind == 0:
                ok = editor.move_node(nid, float(rng.uniform(0, 50)), float(rng.uniform(0, 20)))
            elif kind == 1:
                ok = editor.set_name(nid, f"n{k}")
            elif kind == 2:
                new = editor.add_node(float(rng.uniform(0, 50)), 1.0, 0.0, node_id=f"T{tab}_{k}")
                ok = new is not None
                if ok:
                    mine[tab].append(new)
            else:
                other = [i for i in pool if i != nid]
                ok = bool(other) and editor.connect(nid, other[rng.integers(len(other))])
        if ok and tab == B:
            only_b = carry(only_b, editor.history[-1].before, editor.history[-1].after)
    with editor.by(A):
        while editor.undo():
            pass
        assert editor.message == "nothing of this tab to undo"
    assert {n.id: n for n in editor.graph.nodes} == {n.id: n for n in only_b.nodes}
    assert set(editor.graph.edges) == set(only_b.edges)


def test_carry_refuses_a_change_onto_a_landmark_changed_since(editor):
    g0 = editor.graph
    n = g0.node("DS0")
    moved = g0.with_node(n.__class__(n.id, 1.0, 2.0, n.floor, n.rules, n.name))
    other = g0.with_node(n.__class__(n.id, 9.0, 9.0, n.floor, n.rules, n.name))
    with pytest.raises(Conflict) as e:
        carry(other, g0, moved)
    assert e.value.node == "DS0"
    assert carry(g0, g0, moved) == moved
