"""Routes between landmarks (pipeline/reach.py): the lexicographic search (fewest missed
detections, then shortest) against an exhaustive enumeration of simple paths, on random graphs
with rule-less landmarks, one-way edges and floor changes."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from workstation.graph import Landmark, LandmarkGraph
from workstation.pipeline.reach import Reach


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
    holds at most ``max_path`` landmarks. Per target with rules: min (missed, length)."""
    dg, rules = g.digraph, {v.id: v.rules for v in g.nodes}
    best: dict[str, tuple[int, float]] = {}
    stack = [((src,), 0, 0.0, False)]
    while stack:
        path, missed, length, fc = stack.pop()
        u = path[-1]
        if u != src and rules[u]:
            best[u] = min(best.get(u, (99, 0.0)), (missed, length))
        m = missed + (1 if (u != src and rules[u]) else 0)
        if (u != src and (fc or m >= max_hops)) or len(path) >= max_path:
            continue
        for v in dg.successors(u):
            if v not in path:
                e = dg.edges[u, v]
                stack.append((path + (v,), m, length + e["length"], fc or e["floor_change"] != 0))
    return best


@pytest.mark.parametrize("seed", range(6))
def test_routes_are_the_fewest_missed_then_shortest_paths(seed):
    """On graphs small enough to enumerate every path, each landmark with rules gets the route
    an exhaustive search finds; routes to rule-less landmarks are not kept; routes are ordered
    by (missed, length) and each is a path of the graph with the length it states."""
    g = _random_graph(seed)
    reach = Reach(g, max_hops=3)
    reach.MAX_PATH = 6  # paths short enough to enumerate
    dg = g.digraph
    for src in g.ids:
        routes = reach.routes_from(src)
        want = _exhaustive(g, src, 3, 6)
        got = {r.node: (r.missed, r.length) for r in routes}
        assert got.keys() == want.keys()
        for v, (missed, length) in want.items():
            assert got[v][0] == missed and got[v][1] == pytest.approx(length), (src, v)
        keys = [(r.missed, r.length) for r in routes]
        assert keys == sorted(keys)
        for r in routes:
            assert r.path[0] == src and r.path[-1] == r.node
            assert sum(dg.edges[a, b]["length"] for a, b in itertools.pairwise(r.path)) == (
                pytest.approx(r.length)
            )
            assert r.floor_change == any(
                dg.edges[a, b]["floor_change"] != 0 for a, b in itertools.pairwise(r.path)
            )
