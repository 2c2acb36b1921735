"""Landmark-graph PDR (§III-B, eq. 7–14).

Between landmarks: x += l cos θ, y += l sin θ (eq. 7–8) per step, the floor from pressure
(eq. 9, with the building's own floor spacings: :mod:`.floors`). The heading θ is the sensor
heading (gyro, offset-aligned to the graph at each match, or the compass) snapped to the heading
of a graph edge leaving the last landmark when within ε_θ. At each detection the candidates are
the landmarks met next after the last matched one (:mod:`.reach`); at a match the position snaps
to the landmark and the step length is recalibrated as path length / steps (eq. 10).

Which detection is which landmark is decided by :mod:`.association`: ``greedy`` matches each
detection as it comes by the paper's confidence (eq. 11–14); ``hmm`` (the default) keeps the
association hypotheses that best explain the whole walk. docs/decisions.md lists every choice
beyond the paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from workstation.errors import GraphError
from workstation.graph import LandmarkGraph
from workstation.params import PDRParams
from workstation.pipeline.confidence import ALTERNATIVE_START_M, AMBIGUOUS_LOGODDS, circmean, wrap
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import Detections
from workstation.pipeline.reach import Reach
from workstation.pipeline.start import find_start_time
from workstation.pipeline.start import start_time as start_time_of
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.association import associate
from workstation.pipeline.tracking.map_prior import MapPrior, rerank
from workstation.pipeline.tracking.open_by_map import fit_open
from workstation.pipeline.tracking.replay import replay
from workstation.pipeline.tracking.state import (
    END_CHECK_M,
    START_AMBIGUOUS_MARGIN,
    Reranked,
    Track,
    TrackerState,
)
from workstation.pipeline.tracking.tracker import Tracker
from workstation.pipeline.tracking.walk_end import end_on_landmark
from workstation.session import Scalar

#: the distinct surviving starts an inferred start reports (the ambiguity margin is the second's)
START_CANDIDATES = 6

__all__ = ["Track", "circmean", "find_start_time", "track", "wrap"]


def track(
    steps: Steps,
    heading: Heading,
    detections: Detections,
    graph: LandmarkGraph,
    pressure: Scalar | None,
    p: PDRParams,
    start_node: str | None = None,
    start_time: float | None = None,
    _reach: Reach | None = None,
    prior: MapPrior | None = None,
    candidates: int = START_CANDIDATES,
    among: tuple[str, ...] | None = None,
) -> Track:
    """Run the landmark-graph PDR from ``start_node`` (or ``p.start_node``; inferred if neither).
    ``prior``: where a map of the building's other walks puts this walk's scans, weighed in
    choosing among the chains from the best one's start (:mod:`.map_prior`). An inferred start
    keeps up to ``candidates`` distinct surviving starts (``Track.start.candidates``), searched
    ``among`` those landmarks when given (the reach of the walk before's end: walks/chain.py)."""

    start_node = start_node or p.start_node
    found = start_time_of(steps, p, heading) if start_time is None else None
    t0 = found.t if found is not None else float(start_time or 0.0)
    reach = _reach or Reach(graph, p.max_hops)
    trk = Tracker(steps, heading, detections, reach, pressure, p, t0)

    how = found.how if found is not None else "given"
    if not graph.nodes:  # no landmarks yet: plain PDR from the origin
        return _started(replay(trk, trk.start(""), ()), time_how=how)
    for what, node in (("start", start_node), ("end", p.end_node)):
        if node and node not in reach.pos:
            raise GraphError(f"{what} node {node}: not in the landmark graph")
    starts = [start_node] if start_node else list(among or graph.ids)
    ranked = associate(trk, starts)
    chains = _Chains(trk, reach, p, len(detections), ranked)
    sensors, how_map = ranked, Reranked()
    if prior is not None:  # the start and its margin stay the sensors' (map_prior.py)
        # chains as the sensors place them, with their own ends (bent onto a given end, a
        # chain that matched less gains a free fit of the map; mall F1: 3.1 → 10.4 m)
        ranked, how_map = rerank(ranked, prior, p, lambda st: chains.ended(st, None))
    if p.end_node:  # the surveyor's end: the likeliest chain that ends there (walk_end.py)
        ranked = _ending_at_given(
            ranked, lambda st: chains.ended(st).end.how == "given", sensors[0].score
        )
    out = replace(_started(chains.final(ranked[0], prior), time_how=how), map_rerank=how_map)
    if len(starts) > 1 or among:  # one landmark in reach: no alternative (margin inf)
        top = sensors[0]
        out = _started(out, candidates=tuple(
            (st.matches[0].node, round(float(top.score - st.score), 2))
            for st in _distinct_starts(reach, sensors, candidates)))  # fmt: skip
    return out


def _started(track: Track, **start: Any) -> Track:
    """``track`` with its start changed as ``start`` says (:class:`.Start`'s fields)."""
    return replace(track, start=replace(track.start, **start))


class _Chains:
    """The tracks of the association's chains of matches (``sensors``: as the sensors rank
    them), each replayed once — the map, the given end and the chosen chain ask again — and
    ended as the walk is."""

    def __init__(self, trk: Tracker, reach: Reach, p: PDRParams, n_detections: int,
                 sensors: list[TrackerState]) -> None:  # fmt: skip
        self.trk, self.reach, self.p, self.n = trk, reach, p, n_detections
        self.sensors = sensors
        self._replays: dict[int, Track] = {}

    def replayed(self, st: TrackerState) -> Track:
        """The track of chain ``st``: replayed, each match's spread against the others."""
        if id(st) not in self._replays:
            out = replay(self.trk, self.trk.start(st.matches[0].node), st.matches[1:])
            others = [st] + [o for o in self.sensors if o is not st]
            spread = match_spread(self.reach, others, self.n)
            self._replays[id(st)] = replace(
                out, detections=replace(out.detections, spread=spread))
        return self._replays[id(st)]

    def closed(self, tr: Track, given: str | None = "") -> Track:
        """``tr`` with the walk's end closed on a landmark (walk_end.py): the one the surveyor
        gave (``given``; "": ``pdr.end_node``), whatever ``pdr.end_on_landmark`` says, else the
        one the walk alone points at."""
        given = self.p.end_node if given == "" else given
        if given:
            return end_on_landmark(tr, self.reach.pos, given)
        return end_on_landmark(tr, self.reach.pos) if self.p.end_on_landmark else tr

    def ended(self, st: TrackerState, given: str | None = "") -> Track:
        return self.closed(self.replayed(st), given)

    def final(self, st: TrackerState, prior: MapPrior | None) -> Track:
        """The chosen chain's track, ended; a walk that matched nothing turned onto the map,
        unless an end that checks it, or the surveyor's end, outranks the map
        (open_by_map.py)."""
        opened = self.replayed(st)
        out = self.closed(opened)
        if (prior is not None and not self.p.end_node
                and not (out.end.node and out.end.sigma <= END_CHECK_M)):  # fmt: skip
            turned = fit_open(opened, prior, self.p, self.reach.pos)
            if turned.open_fit.scans:
                out = self.closed(turned)
        return out


def _ending_at_given(
    ranked: list[TrackerState], agrees: Callable[[TrackerState], bool], top: float
) -> list[TrackerState]:
    """``ranked`` with the best chain whose end agrees with the end the surveyor gave first,
    among the chains the sensors cannot tell apart (at most ``START_AMBIGUOUS_MARGIN`` less
    likely than their best, ``top``; as the building's map compares them, map_prior.py): a
    chain ending elsewhere contradicts what the surveyor saw. Unchanged when none agrees —
    the walk is then quarantined for it (verdict.py): a chain the sensors find far less
    likely, taken because its end fits, was as often wrong in the middle (mall F1)."""
    for i, st in enumerate(ranked):
        if top - st.score > START_AMBIGUOUS_MARGIN:
            continue
        if agrees(st):
            return ranked if i == 0 else [st, *ranked[:i], *ranked[i + 1 :]]
    return ranked


def match_spread(reach: Reach, ranked: list[TrackerState], n: int) -> np.ndarray:
    """Per detection, the farthest landmark that a chain of matches at most
    ``AMBIGUOUS_LOGODDS`` less likely than the best gives it, from the best chain's landmark
    (inf when on another floor). A chain that ignores the detection offers no other place.
    Beyond the paper (issue #29): on the mall a match with such an alternative ≥ 8 m away was
    wrong 4 times in 10, one without it 1 in 20 — and σ, not the match's eq. 11–14 confidence
    (no better than chance there), is what keeps a wrongly placed scan out of the map."""
    out = np.zeros(n)
    best = ranked[0]
    alts = [
        {m.k: m.node for m in st.matches}
        for st in ranked[1:]
        if best.score - st.score <= AMBIGUOUS_LOGODDS
    ]
    for m in best.matches:
        if m.k < 0:
            continue
        x, y, f = reach.pos[m.node]
        for a in alts:
            v = a.get(m.k)
            if v is None or v == m.node:
                continue
            ax, ay, af = reach.pos[v]
            d = math.hypot(ax - x, ay - y) if af == f else math.inf
            out[m.k] = max(out[m.k], d)
    return out


def _distinct_starts(reach: Reach, ranked: list[TrackerState], most: int) -> list[TrackerState]:
    """The best chain, then the best surviving chains that start somewhere else than every one
    kept before: another floor, or more than ``ALTERNATIVE_START_M`` away."""
    kept: list[TrackerState] = []
    for st in ranked:
        x, y, f = reach.pos[st.matches[0].node]
        if all(
            f != kf or math.hypot(x - kx, y - ky) > ALTERNATIVE_START_M
            for kx, ky, kf in (reach.pos[k.matches[0].node] for k in kept)
        ):
            kept.append(st)
            if len(kept) == most:
                break
    return kept
