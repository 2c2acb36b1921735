"""Routes between landmarks (pipeline/reach.py): the lexicographic search (fewest missed
detections, then shortest) against an exhaustive enumeration of simple paths, on random graphs
with rule-less landmarks, one-way edges and floor changes."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from workstation.graph import Landmark, LandmarkGraph
from workstation.pipeline.reach import Reach
from workstation.sim.building import grid_graph


def _random_graph(seed: int, n: int = 14) -> LandmarkGraph:
    rng = np.random.default_rng(seed)
    nodes = []
    for i in range(n):
        floor = 0.0 if i < n - 3 else 1.0
        rules = frozenset(rng.choice(["gyro", "acc"], rng.integers(0, 2), replace=False))
        if i in (n - 4, n - 3):
            rules = frozenset({"baro_entry", "baro_exit"})
        # irrational-ish coordinates: no two paths tie in length
        nodes.append(Landmark(f"v{i}", *(rng.random(2) * 40 + rng.random() * 1e-3), floor, rules))
    edges = {(f"v{n - 4}", f"v{n - 3}"), (f"v{n - 3}", f"v{n - 4}")}  # the stairs
    for i, j in itertools.combinations(range(n), 2):
        if (nodes[i].floor == nodes[j].floor) and rng.random() < 0.3:
            edges.add((f"v{i}", f"v{j}"))
            if rng.random() < 0.8:  # a few one-way edges
                edges.add((f"v{j}", f"v{i}"))
    return LandmarkGraph(tuple(nodes), tuple(sorted(edges)))


def _exhaustive(g: LandmarkGraph, src: str, max_hops: int, max_path: int):
    """Every simple path from ``src`` that the search may walk: it goes on past a landmark only
    while fewer than ``max_hops`` landmarks with rules were passed and no floor changed, and it
    holds at most ``max_path`` landmarks. Per target with rules: the route that is min (missed,
    length), as (missed, length, edges, changes floor)."""
    dg, rules = g.digraph, {v.id: v.rules for v in g.nodes}
    best: dict[str, tuple] = {}
    stack = [((src,), 0, 0.0, False)]
    while stack:
        path, missed, length, fc = stack.pop()
        u = path[-1]
        if u != src and rules[u]:
            best[u] = min(best.get(u, (99, 0.0)), (missed, length, len(path) - 1, fc))
        m = missed + (1 if (u != src and rules[u]) else 0)
        if (u != src and (fc or m >= max_hops)) or len(path) >= max_path:
            continue
        for v in dg.successors(u):
            if v not in path:
                e = dg.edges[u, v]
                stack.append((path + (v,), m, length + e["length"], fc or e["floor_change"] != 0))
    return best


@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_routes_are_the_fewest_missed_then_shortest_paths(seed, compiled, monkeypatch):
    """On graphs small enough to enumerate every path, each landmark with rules gets the route
    an exhaustive search finds; routes to rule-less landmarks are not kept; routes are ordered
    by (missed, length). Both searches: the Python one, and the compiled one of big graphs."""
    g = _random_graph(seed)
    monkeypatch.setattr(Reach, "COMPILED_MIN", 0 if compiled else 10**9)
    monkeypatch.setattr(Reach, "MAX_PATH", 6)  # paths short enough to enumerate
    reach = Reach(g, max_hops=3)
    assert (reach._compiled is not None) == compiled
    for src in g.ids:
        routes = reach.routes_from(src)
        want = _exhaustive(g, src, 3, 6)
        got = {r.node: r for r in routes}
        assert got.keys() == want.keys()
        for v, (missed, length, edges, fc) in want.items():
            r = got[v]
            assert (r.missed, r.edges, r.floor_change) == (missed, edges, fc), (src, v)
            assert r.length == pytest.approx(length)
        keys = [(r.missed, r.length) for r in routes]
        assert keys == sorted(keys)


@pytest.mark.parametrize("seed", range(4))
def test_compiled_search_is_the_python_search(seed, monkeypatch):
    """The compiled search (graphs of ``COMPILED_MIN`` landmarks or more) gives the same routes,
    in the same order, and the same snapping headings — on graphs with ties (a grid: many
    paths of equal length) as well as without."""
    graphs = [_random_graph(seed, 25), grid_graph(12 + seed)]
    for g in graphs:
        monkeypatch.setattr(Reach, "COMPILED_MIN", 10**9)
        a = Reach(g, 3)
        monkeypatch.setattr(Reach, "COMPILED_MIN", 0)
        b = Reach(g, 3)
        for v in g.ids:
            assert a.routes_from(v) == b.routes_from(v)
            assert np.array_equal(a.headings_from(v), b.headings_from(v))


def test_walks_on_one_graph_share_its_routes():
    """The routes depend on the graph's content and max_hops alone: a second walk on an equal
    graph (another object, as a campaign's worker loads it again) reuses them, from any thread;
    an edited graph or another max_hops gets its own, and only the last two are kept."""
    import threading
    from dataclasses import replace

    from workstation.pipeline.reach import KEPT_GRAPHS, forget_shared, shared

    forget_shared()
    g = _random_graph(3)
    key = lambda g: (g.nodes, g.edges, g.frame, g.floor_heights)  # noqa: E731 — as Pipeline's
    a = shared(g, key(g), 2)
    again = _random_graph(3)
    assert again is not g and shared(again, key(again), 2) is a
    other: list = []
    t = threading.Thread(target=lambda: other.append(shared(g, key(g), 2)))
    t.start()
    t.join()
    assert other == [a]
    assert shared(g, key(g), 3) is not a
    moved = LandmarkGraph(
        (replace(g.nodes[0], x=g.nodes[0].x + 1.0),) + g.nodes[1:], g.edges, g.frame
    )
    assert shared(moved, key(moved), 2) is not a
    assert KEPT_GRAPHS == 2 and shared(g, key(g), 2) is not a  # a was the oldest of three
    forget_shared()


@pytest.mark.parametrize("seed", range(5))
def test_snapping_picks_the_nearest_edge_heading_across_pi(seed):
    """Eq. 7–8's snapping by bisection against the table of every wrapped difference: each θ
    moves onto the nearest heading when within ε — headings near ±π included (their nearest
    neighbour is across the wrap) — and stays put otherwise."""
    from workstation.pipeline.tracking.tracker import _snap

    rng = np.random.default_rng(seed)
    for _ in range(400):
        h = np.sort(rng.uniform(-np.pi, np.pi, rng.integers(1, 40)))
        if rng.random() < 0.3:
            h = np.sort(np.append(h, [np.pi - 1e-3, -np.pi + 1e-3][: rng.integers(1, 3)]))
        theta = rng.uniform(-3 * np.pi, 3 * np.pi, rng.integers(1, 200))
        eps = rng.uniform(0.05, 0.6)
        d = (h[None, :] - theta[:, None] + np.pi) % (2 * np.pi) - np.pi
        dk = d[np.arange(theta.size), np.abs(d).argmin(axis=1)]
        want = np.where(np.abs(dk) < eps, theta + dk, theta)
        np.testing.assert_array_equal(_snap(theta, h, eps), want)
    assert _snap(np.array([3.1]), np.array([-3.1]), 0.2)[0] == pytest.approx(
        3.1 + (2 * np.pi - 6.2)
    )
