"""The paper's pipeline for one walk, one module per stage (the tracking stage a package of
its own, :mod:`.tracking`), each a pure function returning a frozen result:

steps → heading → landmarks (detections) → tracking (landmark-graph PDR) → belief → radiomap.

Beside the stages: :mod:`.sigma` (each scan's placement σ), :mod:`.verdict` (the quarantine),
:mod:`.metrics` and :mod:`.summary` (what a run says of its walk: summary.json, typed),
:mod:`.reach` (routes between landmarks), :mod:`.floors` (eq. 9), :mod:`.confidence`
(eq. 11–14), :mod:`.start` (the start and its time). What needs many walks is a layer above:
:mod:`workstation.walks`.

:class:`Pipeline` runs them in order, hands each result to observers, and caches results so a
re-run after a parameter or graph change recomputes only the stages that depend on it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Literal, get_args, overload

from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline.belief import Belief, compute_belief
from workstation.pipeline.heading import Heading, estimate_heading
from workstation.pipeline.landmarks import Detections, detect_landmarks, sections
from workstation.pipeline.metrics import summarize
from workstation.pipeline.radiomap import RadioMap, build_radiomap
from workstation.pipeline.reach import Reach
from workstation.pipeline.reach import shared as shared_reach
from workstation.pipeline.start import Region, find_start_time
from workstation.pipeline.steps import Steps, detect_steps
from workstation.pipeline.summary import Summary
from workstation.pipeline.tracking.map_prior import MapPrior
from workstation.pipeline.tracking.run import track
from workstation.pipeline.tracking.state import Track
from workstation.session import Session

#: the pipeline's stages, in order: each one's result is cached until its inputs change
Stage = Literal["steps", "heading", "landmarks", "tracking", "belief", "radiomap"]
STAGES: tuple[Stage, ...] = get_args(Stage)

Observer = Callable[[str, Any, "Pipeline"], None]


@dataclass(frozen=True)
class Result:
    steps: Steps
    heading: Heading
    landmarks: Detections
    track: Track
    belief: Belief
    radiomap: RadioMap

    def summary(
        self, session: Session | None = None, graph: LandmarkGraph | None = None
    ) -> Summary:
        return summarize(self, session, graph)


class Pipeline:
    """Runs the stages for one session; re-runs recompute only what changed."""

    def __init__(
        self,
        session: Session,
        graph: LandmarkGraph,
        params: Params | None = None,
        observers: list[Observer] | None = None,
        prior: MapPrior | None = None,
        start_within: Region | None = None,
    ):
        self.session = session.in_frame(graph.frame)
        # where a radio map of the building's other walks puts this walk's scans: weighed in
        # choosing the chain of matches (map_prior.py; pdr.map_weight)
        self.prior = prior
        self.graph = graph
        self.params = params or Params()
        # a start landmark used when the parameters give none (the editor keeps the start it
        # inferred once, so each edit is not a new search over every landmark); set it to None
        # and call ``forget("tracking")`` to search again
        self.start: str | None = None
        # where an inferred start is searched: (x, y, floor or None: every floor, radius m) —
        # the reach of where the walk recorded just before ended (walks/chain.py); None: anywhere
        self.start_within = start_within
        self.observers: list[Observer] = list(observers or [])
        self._cache: dict[str, tuple[Any, Any]] = {}
        self._reach: tuple[Any, Reach] | None = None
        self._gk: tuple[LandmarkGraph, tuple] | None = None
        self.recomputed: list[str] = []
        self.result: Result | None = None

    @overload
    def last(self, stage: Literal["steps"]) -> Steps | None: ...
    @overload
    def last(self, stage: Literal["heading"]) -> Heading | None: ...
    @overload
    def last(self, stage: Literal["landmarks"]) -> Detections | None: ...
    @overload
    def last(self, stage: Literal["tracking"]) -> Track | None: ...
    @overload
    def last(self, stage: Literal["belief"]) -> Belief | None: ...
    @overload
    def last(self, stage: Literal["radiomap"]) -> RadioMap | None: ...

    def last(self, stage: Stage) -> Steps | Heading | Detections | Track | Belief | RadioMap | None:
        """The most recent result of ``stage`` (None before the first run)."""
        hit = self._cache.get(stage)
        return None if hit is None else hit[1]

    def start_candidates(self, beam_width: int, most: int) -> list[str]:
        """The distinct starts (best first, up to ``most``) that a search over every landmark
        keeps with at least ``beam_width`` chains: wider than a run's own
        ``Track.start.candidates``, for ranking by the building's map (start_by_map.py). The
        sensors alone choose; the pipeline's result is unchanged."""
        r = self.result or self.run()
        p = replace(self.params.pdr, start_node=None,
                    beam_width=max(beam_width, self.params.pdr.beam_width))  # fmt: skip
        reach = self._reach[1] if self._reach is not None else None
        tr = track(r.steps, r.heading, r.landmarks, self.graph, self.session.pressure, p,
                   _reach=reach, candidates=most, among=self.start_among())  # fmt: skip
        return [n for n, _ in tr.start.candidates]

    def start_among(self) -> tuple[str, ...] | None:
        """The landmarks of the graph within :attr:`start_within` (None: every landmark)."""
        return self.graph.within(*self.start_within) or None if self.start_within else None

    def _graph_key(self, graph: LandmarkGraph) -> tuple:
        """The graph's content as a cache key: its landmarks, edges, frame, floor heights, σ_L
        (immutable tuples compared by value; the file it came from does not matter)."""
        if self._gk is None or self._gk[0] is not graph:
            key = (
                graph.nodes,
                graph.edges,
                graph.frame,
                graph.floor_heights,
                graph.landmark_sigma_m,
            )
            self._gk = (graph, key)
        return self._gk[1]

    def forget(self, stage: str) -> None:
        """Drop the cached results of ``stage`` and every stage after it."""
        for name in STAGES[STAGES.index(stage) :]:
            self._cache.pop(name, None)

    def run(self, params: Params | None = None, graph: LandmarkGraph | None = None) -> Result:
        if params is not None:
            self.params = params
        if graph is not None:
            self.graph = graph
        p, s = self.params, self.session
        gk = self._graph_key(self.graph)
        self.recomputed = []

        def stage(name: str, key: Any, fn: Callable[[], Any]) -> Any:
            hit = self._cache.get(name)
            if hit is not None and hit[0] == key:
                value = hit[1]
            else:
                value = fn()
                self._cache[name] = (key, value)
                self.recomputed.append(name)
            for ob in self.observers:
                ob(name, value, self)
            return value

        k_steps = ("steps", p.steps)
        steps = stage("steps", k_steps, lambda: detect_steps(s.accelerometer, p.steps))
        k_head = ("heading", p.heading)
        heading = stage("heading", k_head, lambda: estimate_heading(s, p.heading))
        k_lm = (k_steps, k_head, *(getattr(p, sec, None) for sec in sections()))
        landmarks = stage(
            "landmarks",
            k_lm,
            lambda: detect_landmarks(steps, heading, s.pressure, p),
        )
        start = self.start if (self.start and not p.pdr.start_node) else None
        if start is not None and start not in self.graph.ids:
            start = self.start = None  # the kept start was deleted: infer again
        prior = self.prior if p.pdr.map_weight > 0 else None
        # keeping an inferred start does not invalidate its result
        among = self.start_among() if start is None and not p.pdr.start_node else None
        k_tr = (k_lm, gk, p.pdr, prior.key if prior is not None else "", among)
        if self._reach is None or self._reach[0] != (gk, p.pdr.max_hops):
            self._reach = ((gk, p.pdr.max_hops), shared_reach(self.graph, gk, p.pdr.max_hops))
        reach = self._reach[1]
        tr = stage(
            "tracking",
            k_tr,
            lambda: track(
                steps,
                heading,
                landmarks,
                self.graph,
                s.pressure,
                p.pdr,
                start,
                _reach=reach,
                prior=prior,
                among=among,
            ),
        )
        k_bel = (k_tr, p.belief)
        bel = stage("belief", k_bel, lambda: compute_belief(steps, tr, p.belief))
        k_rm = (k_bel, p.radiomap)
        lm = {n.id: (n.x, n.y, n.floor) for n in self.graph.nodes}
        rm = stage(
            "radiomap",
            k_rm,
            lambda: build_radiomap(
                s.wifi, tr, bel, p.radiomap, lm, s.pressure, self.graph.landmark_sigma_m, heading
            ),
        )
        self.result = Result(steps, heading, landmarks, tr, bel, rm)
        for ob in self.observers:
            ob("done", self.result, self)
        return self.result


def run_pipeline(session: Session, graph: LandmarkGraph, params: Params | None = None) -> Result:
    return Pipeline(session, graph, params).run()


__all__ = [
    "STAGES",
    "Belief",
    "Detections",
    "Heading",
    "Pipeline",
    "RadioMap",
    "Result",
    "Steps",
    "Track",
    "find_start_time",
    "run_pipeline",
]
