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
    """Routes from each landmark, shortest first among those missing fewest detections; searched
    the first time a landmark is asked for (a run whose start is known visits a few dozen
    landmarks of a graph that may have thousands)."""

    MAX_PATH = 12

    def __init__(self, graph: LandmarkGraph, max_hops: int):
        self.g = graph
        self.max_hops = max_hops
        self.pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
        self.rules = {n.id: n.rules for n in graph.nodes}
        dg = graph.digraph
        self._succ = {  # (next landmark, length, changes floor, heading for snapping or None)
            u: [(v, e["length"], e["floor_change"] != 0,
                 round(e["heading"], 9) if e["length"] > 0.5 and e["floor_change"] == 0 else None)
                for v in dg.successors(u) for e in (dg.edges[u, v],)]
            for u in graph.ids
        }  # fmt: skip
        self._found: dict[str, tuple[list[Route], np.ndarray]] = {}
        self._edge_heading: dict[tuple[str, str], float] = {}

    def _get(self, node: str) -> tuple[list[Route], np.ndarray]:
        hit = self._found.get(node)
        if hit is None:
            if node not in self._succ:
                return [], np.empty(0)
            hit = self._found[node] = self._search(node, self._succ, self.max_hops)
        return hit

    def routes_from(self, node: str) -> list[Route]:
        """The routes from ``node`` (the candidates of eq. 11 after a match there)."""
        return self._get(node)[0]

    def headings_from(self, node: str) -> np.ndarray:
        """Headings of the edges the walker may follow from ``node`` (snapping, eq. 7–8)."""
        return self._get(node)[1]

    def _search(self, src: str, succ, max_hops: int):
        """Best route to every landmark from ``src``: fewest missed detections, then shortest
        (a lexicographic Dijkstra, each landmark settled once; at most ``MAX_PATH`` nodes). The
        earlier exhaustive search over simple paths took 15 s on a 100-node grid; this is
        O(E log V) per source. A landmark's route is kept as its parent on the best route (the
        parent is settled first, so its route is final); the Route is built when it settles."""
        import heapq

        rules = self.rules
        best: dict[str, tuple[int, float]] = {src: (0, 0.0)}
        # per landmark on its best route so far: parent, depth (nodes on the path), changes
        # floor, climb length, missed before it, path length to the last missed
        info: dict[str, tuple] = {src: (None, 1, False, 0.0, 0, 0.0)}
        heap = [(0, 0.0, 0, src)]
        done: dict[str, Route] = {}
        headings: set[float] = set()
        tie = 0
        while heap:
            missed_u, length_u, _, u = heapq.heappop(heap)
            if u in done:
                continue
            parent, depth, fc, climb, missed_before, missed_at = info[u]
            path = (src,) if parent is None else done[parent].path + (u,)
            done[u] = Route(u, length_u, fc, path, climb, missed_before, missed_at)
            missed = missed_before + (1 if (u != src and rules[u]) else 0)
            if u != src and (fc or missed >= max_hops):
                continue  # routes end at a floor change; too many missed detections
            if depth >= self.MAX_PATH:
                continue
            at = length_u if (u != src and rules[u]) else missed_at
            for v, length, changes, heading in succ[u]:
                if v in done:  # (every landmark on u's path is: no cycles)
                    continue
                if heading is not None:
                    headings.add(heading)
                cost = (missed, length_u + length)
                old = best.get(v)
                if old is not None and old <= cost:
                    continue
                best[v] = cost
                info[v] = (u, depth + 1, fc or changes, climb + (length if changes else 0.0),
                           missed, at)  # fmt: skip
                tie += 1
                heapq.heappush(heap, (cost[0], cost[1], tie, v))
        done.pop(src)
        out = sorted(done.values(), key=lambda r: (r.missed, r.length))
        return out, np.array(sorted(headings))

    def first_edge_heading(self, route: Route) -> float:
        return self.edge_heading(route.path[0], route.path[1])

    def edge_heading(self, u: str, v: str) -> float:
        h = self._edge_heading.get((u, v))
        if h is None:
            h = self._edge_heading[u, v] = float(self.g.digraph.edges[u, v]["heading"])
        return h

    def last_edge_heading(self, route: Route) -> float:
        return float(self.g.digraph.edges[route.path[-2], route.path[-1]]["heading"])
