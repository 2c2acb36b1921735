"""Which landmarks the walker can meet next (the candidates of eq. 11), pre-computed per graph.

From each landmark the routes run along the graph's directed edges. Landmarks without rules
cannot be detected, so passing them is free (up to ``MAX_PATH`` nodes); passing a landmark *with*
rules means its detection was missed, which ``max_hops`` bounds and the association pays for.
Routes end at a floor change: its exit is matched first.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..graph import LandmarkGraph


class Route(NamedTuple):
    """One way from a source landmark to ``node``."""

    node: str
    length: float  # horizontal length of the path (m)
    floor_change: bool  # the path changes floor (stairs, elevator)
    path: tuple[str, ...]  # source .. node
    climb_length: float  # horizontal length of the floor-changing edges on it
    missed: int  # landmarks with rules passed on the way (detections missed)
    missed_at: float  # path length to the last of them (0 if none)


class Reach:
    """Routes from every landmark, shortest first among those missing fewest detections."""

    MAX_PATH = 12

    def __init__(self, graph: LandmarkGraph, max_hops: int):
        self.g = graph
        self.pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
        self.rules = {n.id: n.rules for n in graph.nodes}
        self.routes: dict[str, list[Route]] = {}
        self.edge_headings: dict[str, np.ndarray] = {}
        dg = graph.digraph
        for src in graph.ids:
            out: dict[str, Route] = {}
            headings: set[float] = set()
            # (node, length, floor change, path, climb length, missed, missed_at)
            stack = [Route(src, 0.0, False, (src,), 0.0, 0, 0.0)]
            while stack:
                r = stack.pop()
                for v in dg.successors(r.node):
                    if v in r.path:
                        continue
                    e = dg.edges[r.node, v]
                    changes = e["floor_change"] != 0
                    if e["length"] > 0.5 and not changes:
                        headings.add(round(e["heading"], 9))
                    nxt = Route(
                        v,
                        r.length + e["length"],
                        r.floor_change or changes,
                        r.path + (v,),
                        r.climb_length + (e["length"] if changes else 0.0),
                        r.missed,
                        r.missed_at,
                    )
                    old = out.get(v)
                    if old is None or (nxt.missed, nxt.length) < (old.missed, old.length):
                        out[v] = nxt
                    missed = r.missed + (1 if self.rules[v] else 0)
                    if not nxt.floor_change and missed < max_hops and len(nxt.path) < self.MAX_PATH:
                        stack.append(
                            nxt._replace(
                                missed=missed,
                                missed_at=nxt.length if self.rules[v] else r.missed_at,
                            )
                        )
            self.routes[src] = sorted(out.values(), key=lambda r: (r.missed, r.length))
            self.edge_headings[src] = np.array(sorted(headings))

    def first_edge_heading(self, route: Route) -> float:
        return float(self.g.digraph.edges[route.path[0], route.path[1]]["heading"])

    def last_edge_heading(self, route: Route) -> float:
        return float(self.g.digraph.edges[route.path[-2], route.path[-1]]["heading"])
