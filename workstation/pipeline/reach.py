"""Which landmarks the walker can meet next (the candidates of eq. 11), pre-computed per graph.

From each landmark the routes run along the graph's directed edges. Landmarks without rules
cannot be detected, so passing them is free (up to ``MAX_PATH`` nodes); passing a landmark *with*
rules means its detection was missed, which ``max_hops`` bounds and the association pays for.
Routes end at a floor change: its exit is matched first.
"""

from __future__ import annotations

import heapq
import threading
from collections import OrderedDict
from typing import NamedTuple

import numpy as np

from workstation.graph import LandmarkGraph


class Route(NamedTuple):
    """One way from a source landmark to ``node``."""

    node: str
    length: float  # horizontal length of the path (m)
    floor_change: bool  # the path changes floor (stairs, elevator)
    edges: int  # edges on the path (1: along one edge from the source)
    climb_length: float  # horizontal length of the floor-changing edges on it
    missed: int  # landmarks with rules passed on the way (detections missed)
    missed_at: float  # path length to the last of them (0 if none)


class Reach:
    """Routes from each landmark, shortest first among those missing fewest detections; searched
    the first time a landmark is asked for (a run whose start is known visits a few dozen
    landmarks of a graph that may have thousands). Only routes to landmarks *with* rules are
    kept: a detection can be matched at nothing else."""

    MAX_PATH = 12
    # from this many landmarks on, the search runs compiled (:mod:`._reach_kernel`): with the
    # start inferred every landmark is searched from, 10,000 searches on a 10,000-landmark graph
    COMPILED_MIN = 2000

    def __init__(self, graph: LandmarkGraph, max_hops: int):
        self.g = graph
        self.max_hops = max_hops
        self.pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
        self.rules = {n.id: n.rules for n in graph.nodes}
        self._ids = list(graph.ids)
        self._index = {v: i for i, v in enumerate(self._ids)}
        self._has_rules = [bool(self.rules[v]) for v in self._ids]
        ix = self._index
        self._succ = [  # (next landmark, length, changes floor, heading for snapping or None)
            [(ix[v], e["length"], e["floor_change"] != 0,
              round(e["heading"], 9) if e["length"] > 0.5 and e["floor_change"] == 0 else None)
             for v in graph.successors(u) for e in (graph.edge(u, v),)]
            for u in self._ids
        ]  # fmt: skip
        self._found: dict[str, tuple[list[Route], np.ndarray]] = {}
        self._compiled = None
        self._scratch_lock = threading.Lock()
        if len(self._ids) >= self.COMPILED_MIN:
            from workstation.pipeline._reach_kernel import Scratch

            flat = [(u, *e) for u, es in enumerate(self._succ) for e in es]
            ptr = np.zeros(len(self._ids) + 1, np.int64)
            np.cumsum(np.bincount([f[0] for f in flat], minlength=len(self._ids)), out=ptr[1:])
            self._compiled = (
                Scratch(len(self._ids)),
                ptr,
                np.array([f[1] for f in flat], np.int64),
                np.array([f[2] for f in flat], float),
                np.array([f[3] for f in flat], np.bool_),
                np.array([np.nan if f[4] is None else f[4] for f in flat], float),
                np.array(self._has_rules, np.bool_),
            )
        self._edge_heading: dict[tuple[str, str], float] = {}
        # what other stages derive from these routes alone, kept with them (the candidates'
        # walk-free terms per anchor: candidates.CandidateScoring), keyed by what else it needs
        self.memo: dict[tuple, dict] = {}

    def _get(self, node: str) -> tuple[list[Route], np.ndarray]:
        hit = self._found.get(node)
        if hit is None:
            if node not in self._index:
                return [], np.empty(0)
            search = self._search if self._compiled is None else self._search_compiled
            hit = self._found[node] = search(self._index[node])
        return hit

    def routes_from(self, node: str) -> list[Route]:
        """The routes from ``node`` to landmarks with rules (the candidates of eq. 11 after a
        match there)."""
        return self._get(node)[0]

    def headings_from(self, node: str) -> np.ndarray:
        """Headings of the edges the walker may follow from ``node`` (snapping, eq. 7–8)."""
        return self._get(node)[1]

    def _search(self, src: int) -> tuple[list[Route], np.ndarray]:
        """Best route to every landmark from ``src``: fewest missed detections, then shortest
        (a lexicographic Dijkstra, each landmark settled once; at most ``MAX_PATH`` nodes). The
        earlier exhaustive search over simple paths took 15 s on a 100-node grid; this is
        O(E log V) per source. What a landmark's best route so far needs is kept with it (its
        predecessor is settled first, so the route is final when it settles); a Route is
        built only for a landmark with rules."""
        has_rules, succ, max_hops, max_path = (
            self._has_rules,
            self._succ,
            self.max_hops,
            self.MAX_PATH,
        )
        best: dict[int, tuple[int, float]] = {src: (0, 0.0)}
        # per landmark on its best route so far: depth (nodes on the path), changes floor,
        # climb length, missed before it, path length to the last missed
        info: dict[int, tuple] = {src: (1, False, 0.0, 0, 0.0)}
        heap = [(0, 0.0, 0, src)]
        settled: set[int] = set()
        found: list[tuple] = []
        headings: set[float] = set()
        tie = 0
        pop, push = heapq.heappop, heapq.heappush
        while heap:
            missed_u, length_u, _, u = pop(heap)
            if u in settled:
                continue
            settled.add(u)
            depth, fc, climb, missed_before, missed_at = info[u]
            ruled = u != src and has_rules[u]
            if ruled:
                found.append((missed_before, length_u, u, fc, depth - 1, climb, missed_at))
            missed = missed_before + ruled
            if u != src and (fc or missed >= max_hops):
                continue  # routes end at a floor change; too many missed detections
            if depth >= max_path:
                continue
            at = length_u if ruled else missed_at
            for v, length, changes, heading in succ[u]:
                if v in settled:  # (every landmark on u's path is: no cycles)
                    continue
                if heading is not None:
                    headings.add(heading)
                cost = (missed, length_u + length)
                old = best.get(v)
                if old is not None and old <= cost:
                    continue
                best[v] = cost
                info[v] = (depth + 1, fc or changes, climb + (length if changes else 0.0),
                           missed, at)  # fmt: skip
                tie += 1
                push(heap, (missed, cost[1], tie, v))
        ids = self._ids
        found.sort(key=lambda f: f[:2])  # stable: ties in the order settled
        out = [Route(ids[u], length, fc, edges, climb, missed, at)
               for missed, length, u, fc, edges, climb, at in found]  # fmt: skip
        return out, np.array(sorted(headings))

    def _search_compiled(self, src: int) -> tuple[list[Route], np.ndarray]:
        """:meth:`_search`, compiled: the same routes and headings."""
        assert self._compiled is not None  # only called when compiled
        scratch, ptr, nbr, length, changes, heading, ruled = self._compiled
        ids = self._ids
        with self._scratch_lock:  # one work area: a Reach may be shared between threads
            found = scratch.search(src, ptr, nbr, length, changes, heading, ruled, self.max_hops,
                                   self.MAX_PATH)  # fmt: skip
            out = [Route(ids[v], d, f, e, c, m, a)
                   for v, d, f, e, c, m, a in zip(*(x.tolist() for x in found[:-1]))]  # fmt: skip
            return out, np.array(found[-1])

    def edge_heading(self, u: str, v: str) -> float:
        """Heading of the edge u → v (rad): of a route along one edge, from its source."""
        h = self._edge_heading.get((u, v))
        if h is None:
            h = self._edge_heading[u, v] = float(self.g.edge(u, v)["heading"])
        return h


# Reaches kept for the next walk on the same graph (``shared``), process-wide
_KEPT: OrderedDict[tuple, Reach] = OrderedDict()
_KEPT_LOCK = threading.Lock()
KEPT_GRAPHS = 2


def shared(graph: LandmarkGraph, key: tuple, max_hops: int) -> Reach:
    """The :class:`Reach` of ``graph`` (whose content is ``key``) for ``max_hops``, kept for the
    next walk run on the same graph. With the start inferred every landmark is searched from, a
    fixed cost per walk that does not scale with the walk (issue #28: on a 30-s mall walk a
    quarter of the run); the routes depend only on the graph and ``max_hops``, so the walks of
    one building share them — also in a campaign worker that loads the graph again per walk
    (the key is the content). The ``KEPT_GRAPHS`` graphs used last are kept (two: a worker
    alternating between two buildings; the editor's graph before an edit and after), each as
    large as its routes (tens of MB for a 10,000-landmark graph searched from every landmark)."""
    k = (key, max_hops)
    with _KEPT_LOCK:
        hit = _KEPT.get(k)
        if hit is None:
            hit = _KEPT[k] = Reach(graph, max_hops)
            while len(_KEPT) > KEPT_GRAPHS:
                _KEPT.popitem(last=False)
        else:
            _KEPT.move_to_end(k)
    return hit


def forget_shared() -> None:
    """Drop the kept routes (the next walk searches its graph's routes again)."""
    with _KEPT_LOCK:
        _KEPT.clear()
