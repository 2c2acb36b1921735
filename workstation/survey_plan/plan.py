"""The survey plan: which way to walk, split into recordings, and what to do at each landmark.

:func:`plan_survey` covers the required edges (every level edge, or the thin ones of a map) by
the route of :mod:`.postman`, priced in seconds by the :class:`~.pace.Pace`; floor-change
edges are ways between floors, not required (no scan on a stair is a reference point). A graph
in pieces that no edge joins is planned piece by piece. The route is cut into walks of at most
``max_minutes`` that begin and end at landmarks with a detection rule (a start the pipeline can
be told and an end it can match). At each landmark the plan says what the pipeline needs to see
it (:func:`visit`): a stop of ``pace.stop_s`` at an ``acc`` landmark, the turn at a ``gyro`` one
(a straight pass is not seen, and says so), the stairs or lift at a barometer one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import networkx as nx
import numpy as np

from workstation.graph import LandmarkGraph
from workstation.rules import FLOOR_CHANGE, STOP, TURN
from workstation.survey_plan.pace import Pace, default_pace
from workstation.survey_plan.postman import Route, matching_bound, postman

TURN_DEG = 45.0  # a change of direction the gyro rule sees (ε_gyro: a turn, not a sway)
BACK_DEG = 150.0  # … and one that is turning back


@dataclass(frozen=True)
class Visit:
    """Arriving at ``node``: the turn made there (degrees, + left; None at a walk's ends), how
    long to stand, the instruction, and whether a rule of the landmark will fire."""

    node: str
    turn_deg: float | None
    stop_s: float
    action: str
    seen: bool


@dataclass(frozen=True)
class Leg:
    frm: str
    to: str
    floor_from: float
    floor_to: float
    kind: str  # level, stairs, lift
    length_m: float
    seconds: float


@dataclass(frozen=True)
class Walk:
    index: int
    legs: tuple[Leg, ...]
    visits: tuple[Visit, ...]  # one per node: the start, each landmark reached, the end

    @property
    def start(self) -> str:
        return self.visits[0].node

    @property
    def end(self) -> str:
        return self.visits[-1].node

    @property
    def distance_m(self) -> float:
        return sum(leg.length_m for leg in self.legs)

    standing_s: float  # on the way: the plan's stops or the building's habit (Pace.standing_s)

    @property
    def moving_s(self) -> float:
        return sum(leg.seconds for leg in self.legs)

    @property
    def duration_s(self) -> float:
        return self.moving_s + self.standing_s + self.visits[0].stop_s + self.visits[-1].stop_s

    def scans(self, pace: Pace) -> int:
        """Scans taken on level ground (walking and standing): each a reference point if the
        pipeline accepts it."""
        level = sum(leg.seconds for leg in self.legs if leg.kind == "level")
        still = self.standing_s + self.visits[0].stop_s + self.visits[-1].stop_s
        return int((level + still) // pace.scan_interval_s)


@dataclass(frozen=True)
class SurveyPlan:
    walks: tuple[Walk, ...]
    pace: Pace
    required: tuple[tuple[str, str], ...]
    routes: tuple[Route, ...]  # one per connected piece of the graph
    bound_s: float  # the matching lower bound of the routes' walking time (postman.py)
    rewalk: bool

    @property
    def route_s(self) -> float:
        return sum(r.cost for r in self.routes)


def arcs(graph: LandmarkGraph, pace: Pace) -> list[tuple[str, str, float]]:
    """Every directed edge with its time to walk."""
    out = []
    for u, v in graph.edges:
        e = graph.edge(u, v)
        out.append((u, v, pace.seconds(e["length"], e["floor_change"])))
    return out


def level_edges(graph: LandmarkGraph) -> list[tuple[str, str]]:
    return [(u, v) for u, v in graph.undirected_pairs() if not graph.edge(u, v)["floor_change"]]


def plan_survey(
    graph: LandmarkGraph,
    pace: Pace | None = None,
    required: list[tuple[str, str]] | None = None,
    start: str | None = None,
    max_minutes: float | None = None,
) -> SurveyPlan:
    """The plan that walks ``required`` (default: every level edge) — closed, or open from
    ``start`` — cut into walks of at most ``max_minutes``."""
    pace = pace or default_pace()
    rewalk = required is not None
    req = level_edges(graph) if required is None else list(required)
    if start is not None and start not in graph.ids:
        raise ValueError(f"start landmark {start!r} is not in the graph")
    all_arcs = arcs(graph, pace)
    oneway = frozenset((u, v) for u, v in graph.edges if not graph.has_edge(v, u))
    pieces = sorted(
        nx.weakly_connected_components(graph.digraph), key=lambda c: (start not in c, -len(c))
    )
    routes: list = []
    walks: list = []
    bound = 0.0
    max_s = max_minutes * 60.0 if max_minutes else math.inf
    for piece in pieces:
        r_req = [e for e in req if e[0] in piece]
        if not r_req:
            continue
        s = start if start in piece else None
        r_arcs = [a for a in all_arcs if a[0] in piece]
        route = postman(r_arcs, r_req, s, oneway)
        routes.append(route)
        if not oneway:
            bound += matching_bound(r_arcs, [*r_req, *route.connectors], s)
        for nodes in split(graph, route.nodes, pace, max_s):
            walks.append(route_walk(graph, nodes, pace, len(walks) + 1))
    if oneway:
        bound = math.nan  # the matching bound is for two-way graphs
    return SurveyPlan(tuple(walks), pace, tuple(req), tuple(routes), bound, rewalk)


def _heading(graph: LandmarkGraph, u: str, v: str) -> float | None:
    a, b = graph.node(u), graph.node(v)
    if math.hypot(b.x - a.x, b.y - a.y) < 0.5:
        return None  # a lift: no direction
    return math.atan2(b.y - a.y, b.x - a.x)


def _turn(h_in: float | None, h_out: float | None) -> float | None:
    if h_in is None or h_out is None:
        return None
    return math.degrees(math.atan2(math.sin(h_out - h_in), math.cos(h_out - h_in)))


def visit(graph: LandmarkGraph, node: str, turn: float | None, floors: tuple, pace: Pace) -> Visit:
    """What to do at ``node`` reached on the way (not a walk's start or end): ``floors`` are
    (floor arrived from, floor left to)."""
    rules = graph.node(node).rules
    parts, seen, stop = [], False, 0.0
    if turn is None or abs(turn) < TURN_DEG:
        how = "straight on"
    elif abs(turn) >= BACK_DEG:
        how = "turn back"
    else:
        how = f"turn {'left' if turn > 0 else 'right'} {abs(turn):.0f}°"
    if TURN in rules and turn is not None and abs(turn) >= TURN_DEG:
        seen = True
    if STOP in rules:
        stop, seen = pace.stop_s, True
        parts.append(f"stop {stop:.0f} s")
    if rules & FLOOR_CHANGE and floors[0] != floors[1]:
        seen = True
    parts.insert(0, how)
    text = ", ".join(parts) + (" (not seen walked like this)" if rules and not seen else "")
    return Visit(node, turn, stop, text, seen)


def route_walk(graph: LandmarkGraph, nodes, pace: Pace, index: int = 1) -> Walk:
    """One recording along ``nodes`` (consecutive repeats dropped): its legs, in straight lines,
    and what to do at each landmark."""
    seq = [n for i, n in enumerate(nodes) if i == 0 or n != nodes[i - 1]]
    legs, heads = [], []
    for u, v in zip(seq[:-1], seq[1:]):
        a, b = graph.node(u), graph.node(v)
        run = math.hypot(b.x - a.x, b.y - a.y)
        fc = b.floor - a.floor
        legs.append(Leg(u, v, a.floor, b.floor, pace.kind(run, fc), run, pace.seconds(run, fc)))
        heads.append(_heading(graph, u, v))
    first = f"start recording, stand still {pace.stand_s:.0f} s, then walk"
    visits = [Visit(seq[0], None, pace.stand_s, first, bool(graph.node(seq[0]).rules))]
    h_in = None
    for i in range(1, len(seq) - 1):
        h_in = heads[i - 1] if heads[i - 1] is not None else h_in
        floors = (legs[i - 1].floor_from, legs[i].floor_to)
        v = visit(graph, seq[i], _turn(h_in, heads[i]), floors, pace)
        if legs[i].kind != "level":
            v = replace(
                v, action=f"{v.action}, take the {legs[i].kind} to floor {legs[i].floor_to:g}"
            )
        visits.append(v)
    if len(seq) > 1:
        end = f"stop, stand {pace.stop_s:.0f} s, end the recording"
        visits.append(Visit(seq[-1], None, pace.stop_s, end, bool(graph.node(seq[-1]).rules)))
    moving = sum(leg.seconds for leg in legs)
    standing = pace.standing_s(moving, sum(v.stop_s for v in visits[1:-1]))
    return Walk(index, tuple(legs), tuple(visits), standing)


def split(graph: LandmarkGraph, nodes, pace: Pace, max_s: float) -> list[tuple[str, ...]]:
    """``nodes`` cut into walks of at most ``max_s`` seconds (stand, legs, stops), each ending
    at a landmark with a rule where the next begins. A stretch between two such landmarks that
    alone takes longer is one walk of its own (over the limit: the plan says so)."""
    nodes = list(nodes)
    if len(nodes) < 2 or not math.isfinite(max_s):
        return [tuple(nodes)]
    whole = route_walk(graph, nodes, pace)
    leg_t = np.concatenate([[0.0], np.cumsum([leg.seconds for leg in whole.legs])])
    stop_t = np.concatenate([[0.0], np.cumsum([v.stop_s for v in whole.visits[1:-1]]), [0.0]])
    stop_t[-1] = stop_t[-2]  # stop_t[k]: the stops at nodes 1..k of the whole route
    can_end = np.array([bool(graph.node(n).rules) for n in nodes])
    can_end[-1] = True
    out, i = [], 0
    while i < len(nodes) - 1:
        j = np.arange(i + 1, len(nodes))
        # stand at i, legs i..j, standing on the way (Pace.standing_s), the end stop at j
        moving = leg_t[j] - leg_t[i]
        k = pace.still_share / (1.0 - pace.still_share)
        standing = np.maximum(stop_t[j - 1] - stop_t[i], k * moving)
        dur = pace.stand_s + moving + standing + pace.stop_s
        ok = can_end[j] & (dur <= max_s)
        if ok.any():
            best = int(j[np.flatnonzero(ok)[-1]])
        else:
            best = int(j[np.flatnonzero(can_end[j])[0]])
        out.append(tuple(nodes[i : best + 1]))
        i = best
    return out
