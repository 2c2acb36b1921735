"""The landmark graph as Rerun draws it, one floor at a time: for the per-floor maps
(:mod:`.rerun_log`) and the map that follows the walker's floor (:mod:`.follow`)."""

from __future__ import annotations

import rerun as rr

from ..graph import LandmarkGraph
from .colours import rgb, rule_rgb


def graph_on_floor(graph: LandmarkGraph, f: float) -> tuple[rr.Points2D, rr.LineStrips2D | None]:
    """One floor of the graph as Rerun draws it: landmarks coloured by rule and labelled, and
    the edges on that floor (None when it has none)."""
    nodes = [n for n in graph.nodes if n.floor == f]
    points = rr.Points2D(
        [[n.x, -n.y] for n in nodes], radii=[0.45], colors=[rule_rgb(n.rules) for n in nodes],
        labels=[n.id for n in nodes], show_labels=True,
    )  # fmt: skip
    strips = [
        [[graph.node(u).x, -graph.node(u).y], [graph.node(v).x, -graph.node(v).y]]
        for u, v in graph.undirected_pairs()
        if graph.node(u).floor == f and graph.node(v).floor == f
    ]
    edges = rr.LineStrips2D(strips, colors=[rgb("graph_edges")], radii=[0.12]) if strips else None
    return points, edges
