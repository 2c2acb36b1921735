"""The landmark graph as Rerun draws it, one floor at a time: for the per-floor maps
(:mod:`.rerun_log`) and the map that follows the walker's floor (:mod:`.follow`)."""

from __future__ import annotations

import numpy as np
import rerun as rr

from workstation.graph import LandmarkGraph
from workstation.survey_plan.output import floor_legs
from workstation.viz.colours import rgb, rule_rgb

LABELS_MAX = 80  # landmarks on a floor beyond which ids show on hover only
NODE_RADIUS_M = 0.45
# 2D views draw higher orders on top (Rerun's defaults: lines 20, points 30): the ground truth
# over the reference points and the landmarks, so a fix at a landmark stays in sight
TRUTH_DRAW_ORDER = 40.0
SPARSE_FIXES = 200  # a ground truth of fewer rows is a set of fixes: each drawn as a dot too


def graph_on_floor(graph: LandmarkGraph, f: float) -> dict[str, rr.AsComponents | None]:
    """One floor of the graph as Rerun draws it, by entity under the floor: ``graph/nodes``
    (landmarks coloured by rule, ids on hover), ``graph/labels`` (the ids, None beyond
    ``LABELS_MAX``) and ``graph/edges`` (None when the floor has none).

    The ids hang under their landmark: Rerun puts a point's label box just below its centre,
    where it hid the ground-truth fix at the landmark (the museum's L74/L75, issue #50 item 5),
    so they are logged at invisible points a sphere's radius lower. A floor of more than
    ``LABELS_MAX`` landmarks keeps its ids for hovering: drawn, the mall's 261 boxes hid the plan
    and the walk (the panel thins its labels with the zoom instead; Rerun cannot)."""
    nodes = [n for n in graph.nodes if n.floor == f]
    xy = [[n.x, -n.y] for n in nodes]
    colours = [rule_rgb(n.rules) for n in nodes]
    ids = [n.id for n in nodes]
    points = rr.Points2D(
        xy, radii=[NODE_RADIUS_M], colors=colours, labels=ids, show_labels=False
    )
    labels = (
        rr.Points2D([[x, y + NODE_RADIUS_M] for x, y in xy], radii=[0.0],
                    colors=[_lighter(c) for c in colours], labels=ids, show_labels=True)
        if nodes and len(nodes) <= LABELS_MAX else None
    )  # fmt: skip
    strips = [
        [[graph.node(u).x, -graph.node(u).y], [graph.node(v).x, -graph.node(v).y]]
        for u, v in graph.undirected_pairs()
        if graph.node(u).floor == f and graph.node(v).floor == f
    ]
    edges = rr.LineStrips2D(strips, colors=[rgb("graph_edges")], radii=[0.12]) if strips else None
    return {"graph/nodes": points, "graph/labels": labels, "graph/edges": edges}


def _lighter(c: tuple[int, ...]) -> tuple[int, ...]:
    """A label's text colour: its landmark's, halfway to white (Rerun writes a label in its
    point's colour on a dark box; the moss and blue of the rules read dimly there)."""
    return tuple(int(v + (255 - v) * 0.5) for v in c[:3])


def index_runs(m: np.ndarray) -> list[np.ndarray]:
    """Index runs where ``m`` holds (two samples or more): the pieces of a line on one floor."""
    cut = np.flatnonzero(np.diff(np.flatnonzero(m)) != 1) + 1
    return [r for r in np.split(np.flatnonzero(m), cut) if r.size > 1]


def truth_on_floor(gt, f: float) -> dict[str, rr.AsComponents | None]:
    """The ground truth on floor ``f`` as Rerun draws it: ``ground_truth`` (its stretches on
    that floor, as lines) and ``ground_truth/fixes`` (a sparse truth's fixes as dots; None for a
    dense one), both drawn over the tracks, the reference points and the landmarks."""
    col = [rgb("ground_truth")]
    m = gt.floor == f
    line = rr.LineStrips2D([np.column_stack([gt.x[r], -gt.y[r]]) for r in index_runs(m)],
                           colors=col, radii=[0.06], draw_order=TRUTH_DRAW_ORDER)  # fmt: skip
    fixes = (
        rr.Points2D(np.column_stack([gt.x[m], -gt.y[m]]), colors=col, radii=[0.3],
                    draw_order=TRUTH_DRAW_ORDER + 1)
        if len(gt) < SPARSE_FIXES and m.any() else None
    )  # fmt: skip
    return {"ground_truth": line, "ground_truth/fixes": fixes}


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
