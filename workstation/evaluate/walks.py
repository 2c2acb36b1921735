"""Leave-one-walk-out on any set of walks with sparse ground truth — a surveyor checking their
own building: ``workstation evaluate --walks FILES... --graph G [--params P] --out DIR``.

Each walk is run through the pipeline (start at its first ground-truth fix unless told
otherwise; ``infer``: each walk's start inferred, walks that stood at one place before setting
off deciding theirs together, :mod:`workstation.walks.shared_start`); then each walk in turn is localized on the radio map merged from all the others, for
these kinds of radio map:

- ``ours``: the accepted reference points (placed to within ``radiomap.max_sigma_m``, or the belief filter; scans at landmark stops);
- ``ours_unfiltered``: every scan of the walk placed on our trajectory, nothing filtered;
- ``tap_oracle``: scans placed by interpolating the ground-truth fixes in time — an oracle,
  it knows where the walker was at every fix;
- ``waypoint_pdr``: the organizers' baseline, PDR between consecutive fixes rotated and scaled
  to land on the next (:mod:`workstation.baselines.waypoints`) — it needs the taps too;
- ``pdr_i``: scans placed on plain PDR from the start (compass heading, fixed step length);
- ``tap_oracle_in_map``, ``waypoint_pdr_in_map``: those two baselines from the walks our maps
  hold (quarantined walks left out) — what the quarantine costs, apart from how we place scans.

Errors are pooled over every query scan of every walk (:func:`workstation.stats.error_stats`):
where the floor is right, and over all queries with 15 m per floor of error (the EvAAL score is
the 75th percentile of the latter). A query is *covered* when some other walk passed within
``COVERED_M`` (:mod:`.map_kinds`) of it on its floor (by the ground truth): no radio map built from the others can
place an uncovered query, whatever the method, so the covered figures are given beside. Reference points are checked against the ground truth
interpolated in time: accepted ones, those of trusted segments and those of untrusted closed
segments (the open last segment
is never accepted and would flatter the comparison); belief separates when the points of trusted
segments are placed better than those of untrusted closed segments.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from workstation.errors import InputError, WorkstationError
from workstation.evaluate.map_kinds import (  # fmt: skip
    KINDS,
    SAME_WALKS,
    MapKindResult,
    Penalized,
    covered_by_others,
    map_priors,
    score_built_kinds,
    score_kind,
    score_matchers,
)
from workstation.evaluate.scored_walk import KindMaps, ScoredWalk
from workstation.evaluate.sigma_check import SigmaCheck, held_out, sigma_calibration
from workstation.evaluate.trust import Verdicts, correct_jointly, verdicts
from workstation.evaluate.walk_files import ipin_museum, walk_name  # noqa: F401 - their home before
from workstation.evaluate.walk_scores import Pooled, score_walk, standby_joined, stats_of
from workstation.fingerprints.devices import one_model
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.params import LocalizeParams, Params
from workstation.pipeline import Pipeline
from workstation.pipeline.metrics import pooled_fix_metrics
from workstation.pipeline.start import resolve_end, resolve_start
from workstation.pipeline.summary import Figure
from workstation.session import load_session
from workstation.walks.shared_start import run_inferring_starts


@dataclass(frozen=True)
class LooResult:
    walks: list[str]
    start: str
    threshold: float  # ε_S used
    tau_dbm: float
    align_devices: bool
    tracking: dict[str, Figure]  # pooled fix metrics (pipeline.metrics)
    per_walk: dict[str, ScoredWalk]  # one row per walk (scored_walk.py)
    loo: dict[str, MapKindResult]
    placement: dict[str, dict[str, float]]  # PLACEMENT → n and error statistics (stats_of)
    notes: list[str] = field(default_factory=list)
    # start "infer": the same metrics before the walks that stood together decided their start
    tracking_each_walk_alone: dict[str, Figure] | None = None
    # walks whose points were kept out of our maps (pipeline/verdict.py), and — the defect
    # that must never happen — walks with a wrong start whose points went into them
    walks_quarantined: int = 0
    wrong_start_in_map: int = 0  # another floor, or more than ALTERNATIVE_START_M from the truth
    # a start landmark other than the first fix's, however near (the same place by the start
    # inference's own measure when within ALTERNATIVE_START_M): named, to be looked at
    other_start_landmark_in_map: list[str] = field(default_factory=list)
    # per map kind: how far its points are from the ground truth interpolated in time (m)
    placement_by_kind: dict[str, dict[str, float]] = field(default_factory=dict)
    # how well σ (pipeline/sigma.py) predicts the placement error: rank correlation and, per σ
    # bin, the scans and their mean error
    sigma_check: SigmaCheck | None = None
    queries_every: int = 0  # N > 1: a split (every N-th walk a query), not leave-one-out
    # the verdicts against the truth (trust.verdicts): walks in the map placed > 5 m off, walks held
    # though placed within 2 m
    verdicts: Verdicts | None = None
    # per matcher of the table (fingerprints/matchers.py): per kind (ours, every row, the tap
    # oracle), the mean error with the floor penalty and on the covered queries (issue #63)
    matchers: dict[str, dict[str, Penalized]] = field(default_factory=dict)
    # per kind of map built from the points (fingerprints/kinds.py): per "source/matcher" (ours
    # or the tap oracle; the selected matcher or 1-NN), the errors (map_kinds.score_built_kinds)
    built_kinds: dict[str, dict[str, Penalized]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """results.json's mapping: every field, each walk's row as :meth:`ScoredWalk.to_json`."""
        out = dataclasses.asdict(dataclasses.replace(self, per_walk={}))
        out["per_walk"] = {n: w.to_json() for n, w in self.per_walk.items()}
        out["sigma_check"] = self.sigma_check.to_json() if self.sigma_check else {}
        return {f.name: out[f.name] for f in dataclasses.fields(self)}


def leave_one_out(
    walks: list[Path],
    graph: LandmarkGraph,
    params: Params | None = None,
    start: str = "first-fix",
    progress=None,
    queries_every: int = 0,
    split_offset: int | None = None,
    end: str | None = None,
    end_for: Collection[str] | None = None,
    start_for: Collection[str] | None = None,
) -> LooResult:
    """Run every walk, then localize each on the radio maps of the others (module doc).
    ``queries_every`` = N: a split instead — the walks sorted by name, every N-th is a query
    walk and the rest make the one map they are all localized on (``split_offset``: the first
    query walk's place in that order, N − 1 unless given). ``end``: every walk's end as a
    surveyor would give it (a landmark id or ``last-fix``; ``pdr.end_node``), with a start
    given (not ``infer``); ``end_for``: only these walks (by name) are given it — those a
    surveyor fixes, e.g. the ones a run with the defaults quarantined. ``start_for``, with
    ``start`` ``infer``: these walks (by name) are given their start (the first fix), as a
    surveyor gives some; the others are inferred, helped by them (walks/chain.py)."""

    base = params or Params()
    lp = base.localize
    walks, sessions, notes = _with_truth(walks, graph)
    names = [walk_name(path) for path in walks]
    if end and start == "infer":
        raise WorkstationError("--end needs a start given (first-fix or a landmark), not infer")
    inferred = _Inferred.of(sessions, names, graph, base, start_for) if start == "infer" else None
    asks = _asks(names, queries_every, split_offset)
    runs = _Runs(sessions, names, graph, base, start, end, end_for, inferred, progress)
    maps, per_walk, pooled = runs.all()
    align = lp.align_devices and not one_model(s.metadata.device for s in sessions)
    if inferred is None and base.pdr.map_weight > 0:
        maps, per_walk, pooled = runs.with_map({n: m for n, m in maps.items() if n not in asks},
                                               lp, align)  # fmt: skip
    # the building's walks correct each other, as in merge and a campaign (trust.py)
    truth = {n: s.ground_truth for n, s in zip(names, sessions)}
    map_sig = correct_jointly(maps, per_walk, asks, lp.tau_dbm, bool(align), SAME_WALKS, truth)
    maps, queries = _split(maps, sessions, names, asks if queries_every > 1 else None)
    loo, matchers, built = _scores(maps, queries, lp, align)
    standby_joined(maps, names, pooled)
    offsets = loo["ours"].query_device_offsets_db
    per_walk = {n: replace(w, device_offset_db=offsets.get(n)) for n, w in per_walk.items()}
    sig = np.vstack(pooled.sig_err) if pooled.sig_err else np.empty((0, 2))
    return LooResult(
        **_start_checks(per_walk),
        placement_by_kind=stats_of(pooled.kind_err),
        queries_every=queries_every,
        sigma_check=SigmaCheck(sigma_calibration(sig), held_out(pooled.sig_terms),
                               sigma_calibration(map_sig)),
        verdicts=verdicts(per_walk, asks),
        walks=list(per_walk),
        start=start,
        threshold=base.belief.threshold,
        tau_dbm=lp.tau_dbm,
        align_devices=bool(align),
        tracking=pooled_fix_metrics(pooled.runs),
        tracking_each_walk_alone=inferred.alone_metrics if inferred is not None else None,
        per_walk=per_walk,
        loo=loo,
        placement=stats_of(pooled.placed),
        notes=notes,
        matchers=matchers,
        built_kinds=built,
    )


def _split(maps: dict, sessions, names: list[str], asks: set[str] | None) -> tuple[dict, dict]:
    """The maps the walks are localized on and the query walks' scans: in a split (``asks``,
    maybe none) the query walks' and the others' maps; in a leave-one-out (None) every walk is
    both."""
    queries = {n: Fingerprints.from_session(s) for n, s in zip(names, sessions)
               if asks is None or n in asks}  # fmt: skip
    return {k: m for k, m in maps.items() if asks is None or k not in asks}, queries


def _scores(maps: dict, queries: dict, lp, align: bool) -> tuple[dict, dict, dict]:
    """Every query walk on the map of the others: per kind of map, per matcher, per kind built
    from the points (:mod:`.map_kinds`)."""
    covered = {
        q: covered_by_others(qf, [m["tap_oracle"] for k, m in maps.items() if k != q])
        for q, qf in queries.items()
    }
    loo = {kind: score_kind(kind, maps, queries, covered, lp, align) for kind in KINDS}
    matchers = score_matchers(maps, queries, covered, lp, align, loo)
    return loo, matchers, score_built_kinds(maps, queries, covered, lp, align)


def _start_checks(per_walk: dict[str, ScoredWalk]) -> dict[str, Any]:
    """The walks quarantined, and of those in the map the ones started elsewhere (the defect
    that must never happen) or at another landmark of the same place (named, to look at)."""
    in_map = {n: w for n, w in per_walk.items() if w.in_map}
    return {
        "walks_quarantined": sum(bool(w.quarantine) for w in per_walk.values()),
        "wrong_start_in_map": sum(not w.start_same_place for w in in_map.values()),
        "other_start_landmark_in_map": [
            n for n, w in in_map.items() if not w.start_right and w.start_same_place
        ],
    }  # fmt: skip


def _asks(names: list[str], every: int, offset: int | None) -> set[str]:
    """A split's query walks: every ``every``-th by name from ``offset`` (``every`` − 1 unless
    given); none in a leave-one-out."""
    first = every - 1 if offset is None else offset
    return set(sorted(names)[first::every]) if every > 1 else set()


def _with_truth(walks: list[Path], graph: LandmarkGraph) -> tuple[list[Path], list, list[str]]:
    """The walks with two ground-truth fixes or more, their sessions in the graph's frame, and
    a note naming the others (nothing to score: left out)."""
    sessions, untapped, kept = [], [], []
    for path in walks:
        s = load_session(path)
        if not s.has_path:
            untapped.append(path)
            continue
        kept.append(path)
        sessions.append(s.in_frame(graph.frame))
    if len(kept) < 2:
        where = untapped[0] if untapped else walks[0] if walks else Path(".")
        why = "has fewer than two ground-truth fixes; " if untapped else ""
        raise InputError(where, f"{why}leave-one-out needs two walks or more with two fixes each")
    notes = (
        [f"left out, fewer than two ground-truth fixes (nothing to score): "
         f"{', '.join(walk_name(p) for p in untapped)}"] if untapped else []
    )  # fmt: skip
    return kept, sessions, notes


@dataclass(frozen=True)
class _Inferred:
    """Start ``infer``: the walks that stood at one place decide their start together — their
    runs, who decided with whom, the starts handed over, the fix metrics each walk alone gave."""

    results: list
    shared: dict[int, str]
    handed: dict
    alone_metrics: dict[str, Figure]

    @classmethod
    def of(cls, sessions, names, graph: LandmarkGraph, base: Params, start_for) -> _Inferred:
        p = base.updated(**{"pdr.start_node": None})
        given = {i for i, n in enumerate(names) if start_for and n in start_for}
        alone = [Pipeline(s, graph, p if i not in given else base.updated(
            **{"pdr.start_node": resolve_start("first-fix", s, graph)})).run()
            for i, s in enumerate(sessions)]  # fmt: skip
        alone_metrics = pooled_fix_metrics([(r, s, graph) for r, s in zip(alone, sessions)])
        results, groups, handed = run_inferring_starts(sessions, graph, base, alone, given, names)
        shared = {i: ", ".join(names[j] for j in g.walks if j != i) for g in groups for i in g.walks}
        return cls(results, shared, handed, alone_metrics)


class _Runs:
    """Every walk run (once per pass; each walk's pipeline kept for the next) and scored."""

    def __init__(self, sessions, names, graph, base: Params, start: str, end, end_for,
                 inferred: _Inferred | None, progress) -> None:  # fmt: skip
        self.sessions, self.names, self.graph, self.base = sessions, names, graph, base
        self.start, self.end, self.end_for = start, end, end_for
        self.inferred, self.progress = inferred, progress
        self.pipes: list = [None] * len(sessions)
        self.priors: dict = {}

    def _run(self, i: int):
        if self.inferred is not None:
            return self.inferred.results[i]
        s, name = self.sessions[i], self.names[i]
        if self.pipes[i] is None:
            p = self.base.updated(**{"pdr.start_node": resolve_start(self.start, s, self.graph)})
            if self.end and (self.end_for is None or name in self.end_for):
                p = p.updated(**{"pdr.end_node": resolve_end(self.end, s, self.graph)})
            self.pipes[i] = Pipeline(s, self.graph, p)
        self.pipes[i].prior = self.priors.get(name)
        return self.pipes[i].run()

    def with_map(
        self, maps: KindMaps, lp: LocalizeParams, align: bool
    ) -> tuple[KindMaps, dict[str, ScoredWalk], Pooled]:
        """A second pass: each walk's chain chosen again with the map of the other walks (their
        first pass, ``maps``: in a split, of the map walks only) as evidence
        (pipeline/map_prior.py)."""
        firsts = {n: m["ours"].without_standby() for n, m in maps.items()}
        wifi = {n: s.wifi for n, s in zip(self.names, self.sessions)}
        self.priors.update(map_priors(firsts, wifi, lp, align))
        return self.all(" again, with the map of the other walks")

    def all(self, again: str = "") -> tuple[KindMaps, dict[str, ScoredWalk], Pooled]:
        maps: KindMaps = {}
        per_walk: dict[str, ScoredWalk] = {}
        pooled = Pooled()
        shared = self.inferred.shared if self.inferred is not None else {}
        for i, s in enumerate(self.sessions):
            name = self.names[i]
            maps[name], per_walk[name] = score_walk(self._run(i), s, self.graph, self.base,
                                                    shared.get(i), pooled)  # fmt: skip
            if self.inferred is not None and i in self.inferred.handed:
                # its start searched within reach of where the walk before ended
                handed = self.inferred.handed[i].handed()
                per_walk[name] = replace(per_walk[name], start_after=handed)
            if self.progress:
                self.progress(i + 1, len(self.sessions), f"ran {name}{again}")
        return maps, per_walk, pooled

