"""Graph errors as a surveyor makes them, for robustness experiments: landmarks drawn off their
true place (N(0, σ) metres in x and y), landmarks whose detection rule was forgotten, edges left
out. The walk is simulated on the true building; the pipeline runs on the perturbed graph."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.rules import FLOOR_CHANGE

BARO = FLOOR_CHANGE


def perturb_graph(
    graph: LandmarkGraph,
    rng: np.random.Generator,
    displace_sd_m: float = 0.0,
    drop_rules: float = 0.0,
    drop_edges: int = 0,
) -> LandmarkGraph:
    """``graph`` with every node displaced by N(0, ``displace_sd_m``), a share ``drop_rules`` of
    the landmarks with turn/stop rules stripped of them, and ``drop_edges`` two-way edges removed (never
    one that would cut a landmark off)."""
    nodes = list(graph.nodes)
    if displace_sd_m > 0:
        d = rng.normal(0.0, displace_sd_m, (len(nodes), 2))
        nodes = [replace(n, x=float(n.x + dx), y=float(n.y + dy)) for n, (dx, dy) in zip(nodes, d)]
    if drop_rules > 0:  # barometer rules stay: a floor change without one is refused
        ruled = [i for i, n in enumerate(nodes) if n.rules - BARO]
        k = int(round(drop_rules * len(ruled)))
        for i in rng.choice(ruled, size=k, replace=False) if k else []:
            nodes[i] = replace(nodes[i], rules=nodes[i].rules & BARO)
    g = replace(graph, nodes=tuple(nodes))
    pairs = sorted({tuple(sorted(e)) for e in g.edges})
    for _ in range(drop_edges):
        degree: dict[str, int] = {}
        for u, v in pairs:
            degree[u] = degree.get(u, 0) + 1
            degree[v] = degree.get(v, 0) + 1
        ok = [p for p in pairs if degree[p[0]] > 1 and degree[p[1]] > 1]
        if not ok:
            break
        u, v = ok[int(rng.integers(len(ok)))]
        g = g.without_edge(u, v)
        pairs.remove((u, v))
    return g
