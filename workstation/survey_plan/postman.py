"""The route that walks every required edge at least once: the route-inspection problem.

Pure maths over a directed multigraph of *arcs* ``(u, v, cost)`` (an undirected edge is its two
arcs). ``required`` edges are walked at least once; every arc may be walked again (deadheading).

**Exact formulation** (mixed Chinese postman as an integer programme, solved by HiGHS through
``scipy.optimize.milp``). Variables: ``x_a ≥ 0`` extra traversals of arc ``a``; for each required
two-way edge ``e = {u, v}`` a binary ``y_e`` (1: its required traversal goes u → v, 0: v → u);
for an open route from ``s`` a binary ``o_v`` (the route ends at v, Σ o_v = 1). At every node
the walk leaves as often as it arrives:

    out(v) − in(v) = [v = s] − o_v      (open)        out(v) − in(v) = 0      (closed)

and the cost Σ c_a x_a is minimal. A balanced, connected directed multigraph has an Euler
circuit (an open one from s to the o-node), so once the required edges are connected the
optimum of this programme *is* the optimal route. For undirected graphs it equals the classical
bound (required length + a minimum-weight perfect matching of the odd-degree nodes on
shortest-path distances, :func:`matching_bound`), which the tests check.

**Connecting** required edges that do not touch (the rural postman, NP-hard in general): the
components of the required edges (and the start) are joined by the shortest paths of a minimum
spanning tree over their pairwise shortest distances (Frederickson's heuristic), and those
paths become required. Exact when the required edges are already connected.
"""

from __future__ import annotations

from dataclasses import dataclass

import networkx as nx
import numpy as np


@dataclass(frozen=True)
class Route:
    """``nodes``: the walk, node after node; ``cost``: its summed arc costs; ``deadhead``: the
    cost walked more than once; ``connectors``: the (u, v) pairs added to join the required
    edges; ``closed``: it ends where it started."""

    nodes: tuple[str, ...]
    cost: float
    required_cost: float
    deadhead: float
    connectors: tuple[tuple[str, str], ...]
    closed: bool


def _cost_graph(arcs) -> nx.DiGraph:
    g = nx.DiGraph()
    for u, v, c in arcs:
        if not g.has_edge(u, v) or c < g.edges[u, v]["cost"]:
            g.add_edge(u, v, cost=float(c))
    return g


def _connect(g: nx.DiGraph, required: list[tuple[str, str]], start: str | None):
    """Shortest paths joining the components of the required edges (and the start): the
    edges of a minimum spanning tree over the components, each a shortest path of arcs."""
    comp = nx.Graph()
    comp.add_edges_from(required)
    if start is not None:
        comp.add_node(start)
    parts = [sorted(c) for c in nx.connected_components(comp)]
    if len(parts) <= 1:
        return []
    und = g.to_undirected(as_view=False)
    for u, v in und.edges:  # a two-way pair costs its cheaper direction
        c = [g.edges[a, b]["cost"] for a, b in ((u, v), (v, u)) if g.has_edge(a, b)]
        und.edges[u, v]["cost"] = min(c)
    which = {n: i for i, p in enumerate(parts) for n in p}
    meta = nx.Graph()
    best: dict[tuple[int, int], tuple[float, list[str]]] = {}
    for i, p in enumerate(parts):
        dist, paths = nx.multi_source_dijkstra(und, set(p), weight="cost")
        for n, d in dist.items():
            j = which.get(n)
            if j is not None and j != i:
                k = (min(i, j), max(i, j))
                if k not in best or d < best[k][0]:
                    best[k] = (d, paths[n])
    for (i, j), (d, _) in best.items():
        meta.add_edge(i, j, weight=d)
    missing = set(range(len(parts))) - set(meta.nodes)
    if missing or not nx.is_connected(meta):
        raise ValueError("the required edges cannot all be reached from one another")
    out = []
    for i, j in nx.minimum_spanning_edges(meta, data=False):
        path = best[(min(i, j), max(i, j))][1]
        out += list(zip(path[:-1], path[1:]))
    return out


def _one_way_trap(g: nx.DiGraph) -> None:
    """One-way edges that leave a part of the graph no way back make every route impossible:
    name that part."""
    if g.number_of_nodes() and not nx.is_strongly_connected(g):
        cond = nx.condensation(g)
        sinks = [n for n in cond.nodes if cond.out_degree(n) == 0]
        part = sorted(cond.nodes[sinks[0]]["members"]) if sinks else sorted(g.nodes)[:1]
        more = f" and {len(part) - 5} more" if len(part) > 5 else ""
        raise ValueError(
            f"one-way edges lead to {', '.join(part[:5])}{more} with no way back: "
            "make an edge two-way or add one"
        )


def postman(
    arcs: list[tuple[str, str, float]],
    required: list[tuple[str, str]],
    start: str | None = None,
    oneway: frozenset[tuple[str, str]] = frozenset(),
) -> Route:
    """The cheapest walk over ``arcs`` that walks every ``required`` edge (each once, either way
    unless the pair is in ``oneway``), closed, or open from ``start`` when given (it may end
    anywhere). ``start`` None: closed, starting at the first required edge's first node."""
    g = _cost_graph(arcs)
    if not required:
        return Route((start,) if start else (), 0.0, 0.0, 0.0, (), start is not None)
    for u, v in required:
        if not (g.has_edge(u, v) or g.has_edge(v, u)):
            raise ValueError(f"required edge {u}-{v} is not an arc")
    _one_way_trap(g)
    connectors = _connect(g, list(required), start)
    seen, req2, req1 = set(), [], []  # two-way and one-way required edges, each once
    for u, v in [*required, *connectors]:
        k = frozenset((u, v))
        if k in seen:
            continue
        seen.add(k)
        if (u, v) in oneway or not g.has_edge(v, u):
            req1.append((u, v))
        elif (v, u) in oneway or not g.has_edge(u, v):
            req1.append((v, u))
        else:
            req2.append((u, v))
    two_way = not req1 and all(g.has_edge(v, u) for u, v in g.edges)
    if two_way:
        walk = _matched_walk(g, req2, start)
    else:
        walk = _milp_walk(g, req2, req1, start)
    walk_cost = float(sum(g.edges[u, v]["cost"] for u, v in zip(walk[:-1], walk[1:])))
    req_cost = float(
        sum(min(g.edges[e]["cost"] for e in ((u, v), (v, u)) if g.has_edge(*e)) for u, v in req2)
        + sum(g.edges[u, v]["cost"] for u, v in req1)
    )
    return Route(
        tuple(walk), walk_cost, req_cost, walk_cost - req_cost, tuple(connectors),
        walk[0] == walk[-1],
    )  # fmt: skip


def _undirected(g: nx.DiGraph) -> nx.Graph:
    """The graph without directions, each pair's cheaper arc."""
    und = nx.Graph()
    for u, v in g.edges:
        c = g.edges[u, v]["cost"]
        if not und.has_edge(u, v) or c < und.edges[u, v]["cost"]:
            und.add_edge(u, v, cost=c)
    return und


def _matched_walk(g: nx.DiGraph, req, start: str | None) -> list[str]:
    """Undirected graphs, exactly: the required edges plus, for each pair of a minimum-weight
    perfect matching of their odd-degree nodes, the shortest path between the two. An open
    route from ``start`` adds a virtual end node joined to ``start`` and at distance 0 from
    every node (its match is where the route ends)."""
    und = _undirected(g)
    m = nx.MultiGraph()
    m.add_edges_from(req)
    end = object()  # the virtual end node
    if start is not None:
        m.add_edge(end, start)
    odd = [n for n in m.nodes if m.degree(n) % 2]
    k = nx.Graph()
    paths: dict = {}
    real = [n for n in odd if n is not end]
    for i, u in enumerate(real):
        dist, path = nx.single_source_dijkstra(und, u, weight="cost")
        for v in real[i + 1 :]:
            k.add_edge(u, v, weight=dist[v])
            paths[(u, v)] = path[v]
        if start is not None:
            k.add_edge(end, u, weight=0.0)
    for u, v in nx.min_weight_matching(k):
        if u is end or v is end:
            m.add_edge(end, v if u is end else u)
            continue
        p = paths.get((u, v)) or paths[(v, u)]
        m.add_edges_from(zip(p[:-1], p[1:]))
    if start is None:
        s = req[0][0]
        return [s] + [v for _, v in nx.eulerian_circuit(m, source=s)]
    inner = [v for _, v in nx.eulerian_circuit(m, source=end)][:-1]  # without the end node
    return inner if inner[0] == start else inner[::-1]


def _balance(idx: dict, arc_list: list, req2, req1) -> tuple[list, list, list, np.ndarray]:
    """The flow balance out(v) − in(v) of every node: the arcs' and the undirected required
    edges' coefficients (rows, columns, values) and the constant parts on the right side."""
    rows, cols, vals = [], [], []
    rhs = np.zeros(len(idx))
    na = len(arc_list)
    for j, (u, v) in enumerate(arc_list):
        rows += [idx[u], idx[v]]
        cols += [j, j]
        vals += [1.0, -1.0]
    for j, (u, v) in enumerate(req2):
        # y=1: u→v (out of u, into v); y=0: v→u. out(u) − in(u) = 2y − 1, at v the opposite
        rows += [idx[u], idx[v]]
        cols += [na + j, na + j]
        vals += [2.0, -2.0]
        rhs[idx[u]] += 1.0
        rhs[idx[v]] -= 1.0
    for u, v in req1:
        rhs[idx[u]] -= 1.0
        rhs[idx[v]] += 1.0
    return rows, cols, vals, rhs


def _milp_walk(g: nx.DiGraph, req2, req1, start: str | None) -> list[str]:
    """The exact mixed-graph route by the integer programme of the module doc."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import coo_matrix

    nodes = sorted(g.nodes)
    idx = {n: i for i, n in enumerate(nodes)}
    arc_list = list(g.edges)
    cost = np.array([g.edges[a]["cost"] for a in arc_list])
    na, n2, nn = len(arc_list), len(req2), len(nodes)
    open_route = start is not None
    nvar = na + n2 + (nn if open_route else 0)
    # rows: out(v) − in(v) for every node; the constant (required) parts go to the right side
    rows, cols, vals, rhs = _balance(idx, arc_list, req2, req1)
    if open_route:
        for i in range(nn):  # + o_v on the left: out − in + o_v = [v = s]
            rows.append(i)
            cols.append(na + n2 + i)
            vals.append(1.0)
        rhs[idx[start]] += 1.0
    a = coo_matrix((vals, (rows, cols)), shape=(nn, nvar)).tocsr()
    cons = [LinearConstraint(a, rhs, rhs)]
    if open_route:
        row = np.zeros(nvar)
        row[na + n2 :] = 1.0
        cons.append(LinearConstraint(row[None, :], 1.0, 1.0))
    c = np.concatenate([cost, np.zeros(nvar - na)])
    ub = np.concatenate([np.full(na, np.inf), np.ones(nvar - na)])
    res = milp(c, constraints=cons, integrality=np.ones(nvar), bounds=Bounds(0.0, ub))
    if res.x is None:
        raise ValueError(f"no route walks every required edge ({res.message})")
    sol = np.round(res.x).astype(int)
    m = nx.MultiDiGraph()
    for j, (u, v) in enumerate(arc_list):
        for _ in range(sol[j]):
            m.add_edge(u, v)
    for j, (u, v) in enumerate(req2):
        m.add_edge(*((u, v) if sol[na + j] else (v, u)))
    for u, v in req1:
        m.add_edge(u, v)
    s: str = start if start is not None else (req2 or req1)[0][0]
    if open_route:
        end = nodes[int(np.argmax(sol[na + n2 :]))]
        walk = [s] + [v for _, v in _euler(m, s, end)]
    else:
        walk = [s] + [v for _, v in nx.eulerian_circuit(m, source=s)]
    return walk


def _euler(m: nx.MultiDiGraph, s: str, end: str | None):
    """An Euler path s → end (end = s: a circuit)."""
    if s == end:
        return list(nx.eulerian_circuit(m, source=s))
    m = m.copy()
    m.add_edge(end, s, key="_close")
    circ = list(nx.eulerian_circuit(m, source=s, keys=True))
    i = next(i for i, (u, v, k) in enumerate(circ) if k == "_close" and u == end)
    return [(u, v) for u, v, _ in circ[i + 1 :] + circ[:i]]


def matching_bound(
    arcs: list[tuple[str, str, float]], required: list[tuple[str, str]], start: str | None = None
) -> float:
    """The classical lower bound of a route that walks every ``required`` edge of an undirected
    graph: their length plus a minimum-weight perfect matching of the nodes of odd required
    degree on shortest-path distances over all ``arcs`` (Edmonds & Johnson 1973); open from
    ``start``, the start's parity flips and one node (the end) is matched for free. Exact when
    the required edges are connected."""
    g = nx.Graph()
    for u, v, c in arcs:
        if not g.has_edge(u, v) or c < g.edges[u, v]["w"]:
            g.add_edge(u, v, w=float(c))
    total, deg, seen = 0.0, dict[str, int](), set[frozenset[str]]()
    for u, v in required:
        if frozenset((u, v)) in seen:
            continue
        seen.add(frozenset((u, v)))
        total += g.edges[u, v]["w"]
        deg[u] = deg.get(u, 0) + 1
        deg[v] = deg.get(v, 0) + 1
    if start is not None:
        deg[start] = deg.get(start, 0) + 1
    odd = sorted(n for n, d in deg.items() if d % 2)
    k = nx.Graph()
    for i, u in enumerate(odd):
        dist = nx.single_source_dijkstra_path_length(g, u, weight="w")
        for v in odd[i + 1 :]:
            k.add_edge(u, v, weight=dist[v])
        if start is not None:
            k.add_edge("\0end", u, weight=0.0)
    if not k.number_of_edges():
        return total
    pairs = nx.min_weight_matching(k)
    return total + sum(k.edges[u, v]["weight"] for u, v in pairs)
