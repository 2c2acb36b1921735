"""The landmark graph as Rerun draws it, one floor at a time: for the per-floor maps
(:mod:`.rerun_log`) and the map that follows the walker's floor (:mod:`.follow`)."""

from __future__ import annotations

import rerun as rr

from workstation.graph import LandmarkGraph
from workstation.survey_plan.output import floor_legs
from workstation.viz.colours import rgb, rule_rgb

LABELS_MAX = 80  # landmarks on a floor beyond which ids show on hover only


def graph_on_floor(graph: LandmarkGraph, f: float) -> tuple[rr.Points2D, rr.LineStrips2D | None]:
    """One floor of the graph as Rerun draws it: landmarks coloured by rule and labelled, and
    the edges on that floor (None when it has none). A floor of more than ``LABELS_MAX``
    landmarks keeps its ids for hovering: drawn, the mall's 261 boxes hid the plan and the walk
    (the panel thins its labels with the zoom instead; Rerun cannot)."""
    nodes = [n for n in graph.nodes if n.floor == f]
    points = rr.Points2D(
        [[n.x, -n.y] for n in nodes], radii=[0.45], colors=[rule_rgb(n.rules) for n in nodes],
        labels=[n.id for n in nodes], show_labels=len(nodes) <= LABELS_MAX,
    )  # fmt: skip
    strips = [
        [[graph.node(u).x, -graph.node(u).y], [graph.node(v).x, -graph.node(v).y]]
        for u, v in graph.undirected_pairs()
        if graph.node(u).floor == f and graph.node(v).floor == f
    ]
    edges = rr.LineStrips2D(strips, colors=[rgb("graph_edges")], radii=[0.12]) if strips else None
    return points, edges


ROUTE_DRAW_ORDER = -10.0  # under the graph (2D views draw higher orders on top)


def route_on_floor(legs, graph: LandmarkGraph, f: float) -> rr.LineStrips2D | None:
    """A survey plan's level legs on floor ``f`` (``legs``: (label, from, to) in walking order),
    labelled walk.leg, drawn under the graph; None when no leg is on that floor."""
    strips, labels = [], []
    for label, u, v in floor_legs(legs, graph, f):
        a, b = graph.node(u), graph.node(v)
        strips.append([[a.x, -a.y], [b.x, -b.y]])
        labels.append(label)
    if not strips:
        return None
    return rr.LineStrips2D(
        strips, colors=[rgb("planned_route")], radii=[0.4], labels=labels,
        draw_order=ROUTE_DRAW_ORDER,
    )  # fmt: skip
