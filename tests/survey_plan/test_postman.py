"""The route-inspection route against brute force on small random graphs, and against the
matching lower bound on the buildings' graphs."""

import itertools
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from workstation.graph import LandmarkGraph
from workstation.sim.building import office2f, office3f
from workstation.survey_plan.pace import default_pace
from workstation.survey_plan.plan import arcs, level_edges
from workstation.survey_plan.postman import matching_bound, postman

MALL = Path(__file__).parents[1] / "data" / "msilc" / "site1_f1_graph.yaml"


def _random_graph(rng, n: int, extra: int) -> list[tuple[str, str, float]]:
    """A connected graph: a random spanning tree plus ``extra`` edges, integer lengths."""
    names = [f"N{i}" for i in range(n)]
    edges = {}
    for i in range(1, n):
        j = int(rng.integers(0, i))
        edges[frozenset((names[i], names[j]))] = float(rng.integers(1, 20))
    while len(edges) < n - 1 + extra:
        a, b = rng.choice(n, 2, replace=False)
        edges.setdefault(frozenset((names[a], names[b])), float(rng.integers(1, 20)))
    return [(*sorted(k), c) for k, c in edges.items()]


def _brute(edges, start=None) -> float:
    """The cheapest augmentation (each edge walked once more or not: enough for undirected
    graphs) leaving every node even — or, open from ``start``, all but ``start`` and one end."""
    best = np.inf
    for dup in itertools.product((0, 1), repeat=len(edges)):
        deg: dict[str, int] = {}
        for (u, v, _), d in zip(edges, dup):
            deg[u] = deg.get(u, 0) + 1 + d
            deg[v] = deg.get(v, 0) + 1 + d
        odd = {k for k, d in deg.items() if d % 2}
        if odd and not (start is not None and start in odd and len(odd) == 2):
            continue
        best = min(best, sum(c * (1 + d) for (_, _, c), d in zip(edges, dup)))
    return best


def _check_walk(route, edges, closed: bool, start=None):
    """A walk along edges, every edge in it, closed or from ``start``; returns its cost."""
    cost = {frozenset((u, v)): c for u, v, c in edges}
    steps = [frozenset(p) for p in zip(route.nodes[:-1], route.nodes[1:])]
    assert all(s in cost for s in steps), "the route leaves the graph"
    assert set(steps) == set(cost), "an edge is not walked"
    if closed:
        assert route.nodes[0] == route.nodes[-1]
    if start is not None:
        assert route.nodes[0] == start
    return sum(cost[s] for s in steps)


@pytest.mark.parametrize("seed", range(8))
def test_closed_route_is_the_brute_force_optimum(seed):
    rng = np.random.default_rng(seed)
    edges = _random_graph(rng, n=int(rng.integers(4, 8)), extra=int(rng.integers(1, 5)))
    both = [(u, v, c) for u, v, c in edges] + [(v, u, c) for u, v, c in edges]
    route = postman(both, [(u, v) for u, v, _ in edges])
    walked = _check_walk(route, edges, closed=True)
    assert walked == pytest.approx(route.cost)
    assert route.cost == pytest.approx(_brute(edges))
    assert route.cost == pytest.approx(matching_bound(both, [(u, v) for u, v, _ in edges]))


@pytest.mark.parametrize("seed", range(8))
def test_open_route_from_a_start_is_the_brute_force_optimum(seed):
    rng = np.random.default_rng(100 + seed)
    edges = _random_graph(rng, n=int(rng.integers(4, 8)), extra=int(rng.integers(1, 5)))
    both = [(u, v, c) for u, v, c in edges] + [(v, u, c) for u, v, c in edges]
    start = edges[int(rng.integers(len(edges)))][0]
    route = postman(both, [(u, v) for u, v, _ in edges], start=start)
    assert _check_walk(route, edges, closed=False, start=start) == pytest.approx(route.cost)
    assert route.cost == pytest.approx(_brute(edges, start))
    req = [(u, v) for u, v, _ in edges]
    assert route.cost == pytest.approx(matching_bound(both, req, start))


def _brute_mixed(arcs_, req2, req1) -> float:
    """Mixed graphs: every orientation of the two-way required edges and up to two extra
    traversals of every arc, balanced and connected."""
    nodes = sorted({u for u, _, _ in arcs_} | {v for _, v, _ in arcs_})
    ix = {n: i for i, n in enumerate(nodes)}
    inc = np.zeros((len(nodes), len(arcs_)))
    for j, (u, v, _) in enumerate(arcs_):
        inc[ix[u], j] += 1
        inc[ix[v], j] -= 1
    cost = np.array([c for _, _, c in arcs_])
    extra = np.array(list(itertools.product((0, 1, 2), repeat=len(arcs_))))
    best = np.inf
    for orient in itertools.product((0, 1), repeat=len(req2)):
        fixed = list(req1) + [(u, v) if o else (v, u) for (u, v), o in zip(req2, orient)]
        b = np.zeros(len(nodes))
        for u, v in fixed:
            b[ix[u]] += 1
            b[ix[v]] -= 1
        ok = np.flatnonzero(np.all(extra @ inc.T + b == 0, axis=1))
        for k in ok[np.argsort(extra[ok] @ cost)]:
            used = [(a[0], a[1]) for a, x in zip(arcs_, extra[k]) if x] + fixed
            if nx.is_weakly_connected(nx.DiGraph(used)):
                best = min(best, float(extra[k] @ cost))
                break
    return best


@pytest.mark.parametrize("seed", range(5))
def test_mixed_route_with_one_way_edges_is_the_brute_force_optimum(seed):
    rng = np.random.default_rng(200 + seed)
    while True:  # two one-way edges that leave every landmark reachable and left again
        edges = _random_graph(rng, n=4, extra=int(rng.integers(1, 3)))
        oneway_i = set(rng.choice(len(edges), 2, replace=False).tolist())
        d = nx.DiGraph()
        for i, (u, v, _) in enumerate(edges):
            d.add_edges_from([(u, v)] if i in oneway_i else [(u, v), (v, u)])
        if nx.is_strongly_connected(d):
            break
    arcs_, req2, req1 = [], [], []
    for i, (u, v, c) in enumerate(edges):
        if i in oneway_i:
            arcs_.append((u, v, c))
            req1.append((u, v))
        else:
            arcs_ += [(u, v, c), (v, u, c)]
            req2.append((u, v))
    oneway = frozenset(req1)
    route = postman(arcs_, req2 + req1, oneway=oneway)
    steps = list(zip(route.nodes[:-1], route.nodes[1:]))
    allowed = {(u, v) for u, v, _ in arcs_}
    assert all(s in allowed for s in steps), "a one-way edge walked the wrong way"
    assert all(e in steps for e in req1)
    assert all((u, v) in steps or (v, u) in steps for u, v in req2)
    required_cost = sum(c for u, v, c in edges)
    assert route.cost == pytest.approx(required_cost + _brute_mixed(arcs_, req2, req1))


def test_one_way_edges_with_no_way_back_are_named():
    a = [("A", "B", 1.0), ("B", "A", 1.0), ("B", "C", 1.0)]  # C is entered, never left
    with pytest.raises(ValueError, match="lead to C with no way back"):
        postman(a, [("A", "B"), ("B", "C")], oneway=frozenset({("B", "C")}))


def _buildings():
    yield "office2f", office2f().graph
    yield "office3f", office3f().graph
    yield "mall F1", LandmarkGraph.load(MALL)


@pytest.mark.parametrize("name", ["office2f", "office3f", "mall F1"])
def test_route_meets_the_matching_bound_on_building_graphs(name):
    graph = dict(_buildings())[name]
    pace = default_pace()
    a = arcs(graph, pace)
    req = level_edges(graph)
    comps = list(nx.weakly_connected_components(graph.digraph))
    total = bound = 0.0
    for c in comps:
        r_req = [e for e in req if e[0] in c]
        if not r_req:
            continue
        r_arcs = [x for x in a if x[0] in c]
        route = postman(r_arcs, r_req)
        total += route.cost
        bound += matching_bound(r_arcs, [*r_req, *route.connectors])
        walked = {frozenset(p) for p in zip(route.nodes[:-1], route.nodes[1:])}
        assert all(frozenset(e) in walked for e in r_req)
    assert total <= 1.01 * bound
    assert total >= bound - 1e-6  # a bound it is
