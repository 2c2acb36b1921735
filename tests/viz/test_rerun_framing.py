"""How Rerun frames the map (issues #30, #50): each floor's view on its landmarks and where the
walk went, the Walker's floor on the walk, a walk without ground truth on its track."""

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.graph import LandmarkGraph
from workstation.session import load_session


def test_each_floor_view_is_framed_on_all_of_its_landmarks(monkeypatch):
    """Issue #30: Rerun framed the plan image and cut landmarks off (museum L08/L09, L34/L35);
    every floor's view is now bounded by its landmarks, 5 m around them."""
    from workstation.sim.building import office3f
    from workstation.viz import layouts
    from workstation.viz.layouts import BOUNDS_PAD_M

    got = {}

    def capture(layout, floors, pressure=True, extents=None, follow=None):
        got.update(extents)

    monkeypatch.setattr(layouts, "blueprint", capture)
    g = office3f().graph
    layouts.default_blueprint("overview", g, None)
    assert set(got) == set(g.floors)
    for n in g.nodes:
        x0, x1, y0, y1 = got[n.floor]
        assert x0 <= n.x <= x1 and y0 <= n.y <= y1
    from workstation.viz.layouts import _bounds

    # x as is, y drawn north up (−y), both padded
    r = _bounds((0.0, 10.0, 2.0, 6.0)).range.as_arrow_array().to_pylist()[0]
    p = BOUNDS_PAD_M
    assert r == {"x_range": [-p, 10 + p], "y_range": [-6 - p, -2 + p]} or list(r.values()) == [
        [-p, 10 + p], [-6 - p, -2 + p]]  # fmt: skip


def test_a_floor_view_also_frames_where_the_walk_went_on_it(monkeypatch):
    """The museum's floor −1 has two landmarks: framed on them alone, its view showed 14 × 21 m
    of a 60-m walk. Given the walk's ground truth, every floor's frame holds it too."""
    from workstation.sim import simulate
    from workstation.viz import layouts

    got = {}
    monkeypatch.setattr(layouts, "blueprint",
                        lambda layout, floors, pressure=True, extents=None, follow=None: got.update(extents))  # fmt: skip
    sim = simulate("office2f", "normal", 1)
    gt = sim.session.ground_truth
    few = type(sim.graph)(sim.graph.nodes[:3], (), sim.graph.frame)  # a sparse graph
    layouts.default_blueprint("overview", few, None, True, sim.session)
    for f in np.unique(gt.floor):
        x0, x1, y0, y1 = got[float(f)]
        on = gt.floor == f
        assert x0 <= gt.x[on].min() and gt.x[on].max() <= x1
        assert y0 <= gt.y[on].min() and gt.y[on].max() <= y1


def test_the_walkers_floor_frames_where_the_walk_went():
    """Issue #50 item 5: the map the walker is on was framed on the whole graph (the mall's
    145 m), the walk a speck in it. Given the walk's ground truth it frames the walk, 5 m around
    it: the Walker's floor tab of a building with floors, the one floor's view of the mall."""
    from workstation.sim import simulate
    from workstation.viz.layouts import BOUNDS_PAD_M, default_blueprint

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    sim = simulate("office2f", "varied", 1)
    cases = [(load_session(ms), LandmarkGraph.load(ms / "graph.yaml"), "Floor 0"),
             (sim.session, sim.graph, "Walker's floor")]  # fmt: skip
    for s, g, name in cases:
        view = next(v for v in _views(default_blueprint("overview", g, None, True, s).root_container)
                    if v.name == name)  # fmt: skip
        (bounds,) = view.properties["VisualBounds2D"].range.as_arrow_array().to_pylist()
        gt = s.in_frame(g.frame).ground_truth
        want = [gt.x.min() - BOUNDS_PAD_M, gt.x.max() + BOUNDS_PAD_M]
        assert bounds["x_range"] == pytest.approx(want), name


def _views(node):
    """Every view under a blueprint container, depth first."""
    for child in getattr(node, "contents", ()):
        if hasattr(child, "origin"):
            yield child
        else:
            yield from _views(child)


def test_a_walk_without_ground_truth_is_framed_on_its_track():
    """Issue #50 item 5: a walk with no ground truth opened framed on the whole graph (the
    mall's 145 m), the walk a speck. `view` sends, after the run, the layout framed 5 m around
    where the run's track went."""
    from dataclasses import replace

    from workstation.pipeline import Pipeline
    from workstation.viz.layouts import BOUNDS_PAD_M, default_blueprint

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    s, g = load_session(ms), LandmarkGraph.load(ms / "graph.yaml")
    bare = replace(s, ground_truth=None)
    tr = Pipeline(bare, g).run().track
    on = tr.steps.segment >= 0
    view = next(v for v in _views(default_blueprint("overview", g, None, False, bare, tr).root_container)
                if v.name == "Floor 0")  # fmt: skip
    (bounds,) = view.properties["VisualBounds2D"].range.as_arrow_array().to_pylist()
    want = [tr.steps.x[on].min() - BOUNDS_PAD_M, tr.steps.x[on].max() + BOUNDS_PAD_M]
    assert bounds["x_range"] == pytest.approx(want)
    framed_on_graph = next(v for v in _views(default_blueprint("overview", g, None, False, bare).root_container)
                           if v.name == "Floor 0")  # fmt: skip
    (before,) = framed_on_graph.properties["VisualBounds2D"].range.as_arrow_array().to_pylist()
    assert before["x_range"] != pytest.approx(want)  # without the track: the graph
