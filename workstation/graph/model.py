"""The landmark graph's records — ``Landmark``, ``LandmarkGraph`` — read, checked and written as
the package doc says."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from workstation.errors import GraphError
from workstation.geo import LocalFrame, distance_to_segments
from workstation.io import graph_read as read
from workstation.io.atomic import atomic_write_text
from workstation.io.store import is_remote, put_text
from workstation.io.yamlio import dump_yaml, parse_yaml_nodes, read_text
from workstation.rules import FLOOR_CHANGE, NAMES

if TYPE_CHECKING:
    import networkx as nx

RULES = NAMES  # the landmark rules (workstation/rules.py)
BARO_RULES = FLOOR_CHANGE
MIN_EDGE_LENGTH_M = 0.05
HPA_PER_M = 0.12  # pressure fall per metre of height near sea level (ρ g ≈ 11.8 Pa/m)


@dataclass(frozen=True)
class Landmark:
    """One landmark v = <(x, y, f), (R_1..R_M)> (eq. 1)."""

    id: str
    x: float
    y: float
    floor: float
    rules: frozenset[str] = frozenset()
    name: str | None = None

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "id": self.id,
            "x": round(self.x, 4),
            "y": round(self.y, 4),
            "floor": _num(self.floor),
            "rules": [r for r in RULES if r in self.rules],
        }
        if self.name:
            d["name"] = self.name
        return d


def _num(v: float):
    return int(v) if float(v).is_integer() else float(v)


@dataclass(frozen=True)
class LandmarkGraph:
    """A validated landmark graph. Immutable: edits return a new graph."""

    nodes: tuple[Landmark, ...]
    edges: tuple[tuple[str, str], ...]  # directed pairs
    frame: LocalFrame | None = None
    source: str | None = None
    floor_heights: tuple[tuple[float, float], ...] = ()  # (floor, height in m) the building states
    landmark_sigma_m: float | None = None  # how well its landmarks are placed (module doc)
    _succ: dict = field(init=False, repr=False, compare=False)  # u → {v: edge attributes}
    _by_id: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        problems = _problems(self.nodes, self.edges)
        if problems:
            raise GraphError("invalid landmark graph:\n  " + "\n  ".join(problems), self.source)
        by_id = {n.id: n for n in self.nodes}
        succ: dict[str, dict[str, dict[str, float]]] = {n.id: {} for n in self.nodes}
        for u, v in self.edges:
            a, b = by_id[u], by_id[v]
            dx, dy = b.x - a.x, b.y - a.y
            succ[u][v] = {"heading": math.atan2(dy, dx), "length": math.hypot(dx, dy),
                          "floor_change": b.floor - a.floor}  # fmt: skip
        object.__setattr__(self, "_succ", succ)
        object.__setattr__(self, "_by_id", by_id)

    @cached_property
    def digraph(self) -> nx.DiGraph:
        """The graph as a networkx ``DiGraph`` (node attributes x, y, floor, rules, name; edge
        attributes as :meth:`edge`), made when first asked: the pipeline reads :meth:`edge` and
        :meth:`successors` and never loads networkx (issue #53: 70 ms of every ``run``)."""
        import networkx as nx

        g = nx.DiGraph()
        for n in self.nodes:
            g.add_node(n.id, x=n.x, y=n.y, floor=n.floor, rules=n.rules, name=n.name)
        for u, out in self._succ.items():
            for v, e in out.items():
                g.add_edge(u, v, **e)
        return g

    # ---- queries -------------------------------------------------------------------------
    def node(self, node_id: str) -> Landmark:
        return self._by_id[node_id]

    @property
    def ids(self) -> list[str]:
        return [n.id for n in self.nodes]

    @property
    def floors(self) -> list[float]:
        return sorted({n.floor for n in self.nodes})

    def successors(self, node_id: str) -> list[str]:
        return list(self._succ[node_id])

    def edge(self, u: str, v: str) -> dict[str, float]:
        """The edge u → v: its ``heading`` (rad), ``length`` (m) and ``floor_change``."""
        return self._succ[u][v]

    def has_edge(self, u: str, v: str) -> bool:
        return v in self._succ.get(u, ())

    def floor_levels_hpa(self) -> dict[float, float] | None:
        """Stated floor heights as pressure falls (hPa) from a common datum, or None."""
        if not self.floor_heights:
            return None
        return {float(f): float(h) * HPA_PER_M for f, h in self.floor_heights}

    def xyf(self) -> np.ndarray:
        """(N, 3) array of node x, y, floor in ``self.ids`` order."""
        return np.array([[n.x, n.y, n.floor] for n in self.nodes], dtype=np.float64).reshape(-1, 3)

    def within(self, x: float, y: float, floor: float | None, r: float) -> tuple[str, ...]:
        """The landmarks within ``r`` m of (x, y) on ``floor`` (None: on every floor)."""
        return tuple(
            n.id
            for n in self.nodes
            if (floor is None or n.floor == floor) and math.hypot(n.x - x, n.y - y) <= r
        )

    def distance_to_edges(self, x, y, floor) -> np.ndarray:
        """Per point (x, y on ``floor``), the distance (m) to the nearest edge on its floor (an
        edge between floors counts on both; inf on a floor without one)."""
        x, y, floor = (np.asarray(v, float) for v in (x, y, floor))
        best = np.full(x.shape, np.inf)
        for fl in np.unique(floor):
            segs = [[[a.x, a.y], [b.x, b.y]] for a, b in ((self.node(u), self.node(v))
                    for u, v in self.undirected_pairs()) if fl in (a.floor, b.floor)]  # fmt: skip
            on = floor == fl
            best[on] = distance_to_segments(x[on], y[on], segs)
        return best

    def undirected_pairs(self) -> list[tuple[str, str]]:
        seen, out = set(), []
        for u, v in self.edges:
            k = frozenset((u, v))
            if k not in seen:
                seen.add(k)
                out.append((u, v))
        return out

    # ---- YAML ----------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {}
        if self.frame is not None:
            d["frame"] = self.frame.to_dict()
        if self.floor_heights:
            d["floors"] = {_num(f): float(h) for f, h in self.floor_heights}
        if self.landmark_sigma_m is not None:
            d["landmark_sigma_m"] = float(self.landmark_sigma_m)
        d["nodes"] = [n.to_dict() for n in self.nodes]
        directed = set(self.edges)
        edges: list[dict[str, Any]] = []
        for u, v in self.undirected_pairs():
            both = (v, u) in directed and (u, v) in directed
            if both:
                edges.append({"from": u, "to": v})
            else:
                a, b = (u, v) if (u, v) in directed else (v, u)
                edges.append({"from": a, "to": b, "oneway": True})
        d["edges"] = edges
        return d

    def to_yaml(self) -> str:
        return dump_yaml(self.to_dict(), sort_keys=False, default_flow_style=None, width=120)

    def save(self, path: str | Path) -> Path | None:
        """Write atomically; the previous file is kept as ``<name>.bak``. Returns the backup.
        ``path`` may be an object in a store (:func:`workstation.io.store.place`): one PUT, the
        previous object copied to ``<name>.bak`` first."""
        if is_remote(path):
            return put_text(path, self.to_yaml(), backup=True)
        return atomic_write_text(path, self.to_yaml(), backup=True)

    @classmethod
    def load(cls, path: str | Path) -> LandmarkGraph:
        path = Path(path)
        text = read_text(path, "graph file")
        return cls.from_yaml(text, source=str(path))

    @classmethod
    def from_yaml(cls, text: str, source: str | None = None) -> LandmarkGraph:
        data, root = parse_yaml_nodes(text, source)  # errors name the file and line
        return cls.from_dict(data, source=source, lines=read.item_lines(root))

    @classmethod
    def from_dict(
        cls, data: Any, source: str | None = None, lines: dict | None = None
    ) -> LandmarkGraph:
        """The graph of a mapping; ``lines``: {"nodes"/"edges": {item: line}} for errors."""
        lines = lines or {}

        def where(section: str, i: int) -> str:
            ln = lines.get(section, {}).get(i)
            return f"{section}[{i}]" + (f" (line {ln})" if ln else "")

        raw_nodes, raw_edges = read.lists(data, source)
        nodes = tuple(
            Landmark(*read.node(rn, where("nodes", i), source)) for i, rn in enumerate(raw_nodes)
        )
        edges = tuple(
            e for i, re_ in enumerate(raw_edges) for e in read.edge(re_, where("edges", i), source)
        )
        heights = read.floor_heights(data.get("floors"), source)
        lsm = read.landmark_sigma(data.get("landmark_sigma_m"), source)
        return cls(nodes, edges, read.frame(data.get("frame"), source), source, heights, lsm)

    # ---- edits (each returns a new, validated graph) -------------------------------------
    def with_node(self, node: Landmark) -> LandmarkGraph:
        """Add ``node``, or replace the node with the same id."""
        nodes = [node if n.id == node.id else n for n in self.nodes]
        if node.id not in self.ids:
            nodes.append(node)
        return replace(self, nodes=tuple(nodes), edges=self.edges)

    def without_node(self, node_id: str) -> LandmarkGraph:
        if node_id not in self.ids:
            raise GraphError(f"node {node_id}: no such node", self.source)
        nodes = tuple(n for n in self.nodes if n.id != node_id)
        edges = tuple(e for e in self.edges if node_id not in e)
        return replace(self, nodes=nodes, edges=edges)

    def with_edge(self, u: str, v: str, oneway: bool = False) -> LandmarkGraph:
        new = [(u, v)] + ([] if oneway else [(v, u)])
        edges = self.edges + tuple(e for e in new if e not in self.edges)
        return replace(self, nodes=self.nodes, edges=edges)

    def without_edge(self, u: str, v: str) -> LandmarkGraph:
        if (u, v) not in self.edges and (v, u) not in self.edges:
            raise GraphError(f"edge {u} -> {v}: no such edge", self.source)
        edges = tuple(e for e in self.edges if e not in ((u, v), (v, u)))
        return replace(self, nodes=self.nodes, edges=edges)


def _problems(nodes: tuple[Landmark, ...], edges: tuple[tuple[str, str], ...]) -> list[str]:
    out: list[str] = []
    by_id: dict[str, Landmark] = {}
    for n in nodes:
        if n.id in by_id:
            out.append(f"node {n.id}: duplicate id")
        by_id[n.id] = n
        bad = sorted(set(n.rules) - set(RULES))
        if bad:
            out.append(f"node {n.id}: unknown rule {bad[0]!r} (known: {', '.join(RULES)})")
        if not all(math.isfinite(v) for v in (n.x, n.y, n.floor)):
            out.append(f"node {n.id}: x, y and floor must be finite numbers")
    seen = set()
    for u, v in edges:
        name = f"edge {u} -> {v}"
        if (u, v) in seen:
            out.append(f"{name}: listed twice")
            continue
        seen.add((u, v))
        missing = [x for x in (u, v) if x not in by_id]
        if missing:
            out.append(f"{name}: unknown node {missing[0]}")
            continue
        if u == v:
            out.append(f"{name}: an edge from a node to itself")
            continue
        a, b = by_id[u], by_id[v]
        length = math.hypot(b.x - a.x, b.y - a.y)
        if a.floor == b.floor and length < MIN_EDGE_LENGTH_M:
            out.append(f"{name}: zero length ({length:.3f} m) on one floor")
        if a.floor != b.floor:
            lacking = [n.id for n in (a, b) if not (n.rules & BARO_RULES)]
            if lacking:
                out.append(
                    f"{name}: joins floors {_num(a.floor)} and {_num(b.floor)} but node {lacking[0]} "
                    "has no barometer rule (baro_entry/baro_exit)"
                )
    return out
