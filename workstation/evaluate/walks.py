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
import math
from collections.abc import Collection
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from workstation.baselines.pdr import pdr
from workstation.baselines.tap import tap_interpolation
from workstation.baselines.waypoints import waypoint_pdr
from workstation.errors import InputError, WorkstationError
from workstation.evaluate.map_kinds import (  # fmt: skip
    KINDS,
    SAME_WALKS,
    MapKindResult,
    covered_by_others,
    map_priors,
    score_built_kinds,
    score_kind,
    score_matchers,
)
from workstation.evaluate.sigma_check import held_out, sigma_calibration
from workstation.evaluate.trust import correct_jointly, verdicts
from workstation.evaluate.walk_files import ipin_museum, walk_name  # noqa: F401 - their home before
from workstation.fingerprints.devices import one_model
from workstation.fingerprints.localize import Fingerprints
from workstation.fingerprints.standby import joins
from workstation.graph import LandmarkGraph
from workstation.params import COMPASS_HEADING, Params
from workstation.pipeline import Pipeline
from workstation.pipeline.confidence import ALTERNATIVE_START_M
from workstation.pipeline.metrics import pooled_fix_metrics
from workstation.pipeline.sigma import terms as sigma_terms
from workstation.pipeline.start import resolve_end, resolve_start
from workstation.session import load_session
from workstation.stats import error_stats
from workstation.walks.shared_start import run_inferring_starts


@dataclass(frozen=True)
class LooResult:
    walks: list[str]
    start: str
    threshold: float  # ε_S used
    tau_dbm: float
    align_devices: bool
    tracking: dict[str, Any]  # pooled fix metrics (pipeline.metrics)
    per_walk: dict[str, dict[str, Any]]
    loo: dict[str, MapKindResult]
    placement: dict[str, dict[str, float]]  # PLACEMENT → n and error statistics
    notes: list[str] = field(default_factory=list)
    # start "infer": the same metrics before the walks that stood together decided their start
    tracking_each_walk_alone: dict[str, Any] | None = None
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
    sigma_check: dict[str, Any] = field(default_factory=dict)
    queries_every: int = 0  # N > 1: a split (every N-th walk a query), not leave-one-out
    # the verdicts against the truth (trust.verdicts): walks in the map placed > 5 m off, walks held
    # though placed within 2 m
    verdicts: dict[str, Any] = field(default_factory=dict)
    # per matcher of the table (fingerprints/matchers.py): per kind (ours, every row, the tap
    # oracle), the mean error with the floor penalty and on the covered queries (issue #63)
    matchers: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    # per kind of map built from the points (fingerprints/kinds.py): per "source/matcher" (ours
    # or the tap oracle; the selected matcher or 1-NN), the errors (map_kinds.score_built_kinds)
    built_kinds: dict[str, dict[str, dict]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


# reference points by how they were placed: every accepted one; those on segments belief trusts;
# every scan of an untrusted closed segment (kept as gap fill or not); the gap fill; the scans
# at landmark stops; the scans held back for their σ that join where no point covers them
PLACEMENT = ("accepted", "trusted_segments", "untrusted_closed", "gap_fill", "at_landmark",
             "standby_joined")  # fmt: skip

PER_WALK_KEYS = (
    "landmark_node_accuracy",
    "landmark_fix_match_rate",
    "landmark_fix_match_rate_strict",
    "floor_accuracy",
    "fix_error_mean_m",
    "reference_points",
    "reference_point_error_mean_m",
    "start_time_s",
    "scans",
    "scans_not_points",
    "chain_by_map",
    "open_by_map",
)


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
    sessions, untapped, kept = [], [], []
    for path in walks:  # a walk without two fixes has nothing to score: left out, and named
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
    walks = kept
    notes = (
        [f"left out, fewer than two ground-truth fixes (nothing to score): "
         f"{', '.join(walk_name(p) for p in untapped)}"] if untapped else []
    )  # fmt: skip
    names = [walk_name(path) for path in walks]
    shared: dict[int, str] = {}
    handed: dict = {}
    alone_metrics, results = None, None
    if end and start == "infer":
        raise WorkstationError("--end needs a start given (first-fix or a landmark), not infer")
    if start == "infer":  # walks that stood at one place decide their start together
        p = base.updated(**{"pdr.start_node": None})
        given = {i for i, n in enumerate(names) if start_for and n in start_for}
        alone = [Pipeline(s, graph, p if i not in given else base.updated(
            **{"pdr.start_node": resolve_start("first-fix", s, graph)})).run()
            for i, s in enumerate(sessions)]  # fmt: skip
        alone_metrics = pooled_fix_metrics([(r, s, graph) for r, s in zip(alone, sessions)])
        results, groups, handed = run_inferring_starts(sessions, graph, base, alone, given, names)
        for g in groups:
            for i in g.walks:
                shared[i] = ", ".join(walk_name(walks[j]) for j in g.walks if j != i)
    first = queries_every - 1 if split_offset is None else split_offset
    asks = set(sorted(names)[first::queries_every]) if queries_every > 1 else set()
    pipes: list = [None] * len(walks)
    priors: dict = {}

    twice = results is None and base.pdr.map_weight > 0
    align = lp.align_devices and not one_model(s.metadata.get("device") for s in sessions)

    def run_all(again: str = ""):
        maps: dict[str, dict[str, Fingerprints]] = {}
        per_walk: dict[str, dict[str, Any]] = {}
        pooled = _Pooled()
        for i, s in enumerate(sessions):
            name = names[i]
            if results is not None:
                r = results[i]
            else:
                if pipes[i] is None:
                    p = base.updated(**{"pdr.start_node": resolve_start(start, s, graph)})
                    if end and (end_for is None or names[i] in end_for):
                        p = p.updated(**{"pdr.end_node": resolve_end(end, s, graph)})
                    pipes[i] = Pipeline(s, graph, p)
                pipes[i].prior = priors.get(name)
                r = pipes[i].run()
            maps[name], per_walk[name] = _score_walk(r, s, graph, base, shared.get(i), pooled)
            if i in handed:  # its start searched within reach of where the walk before ended
                per_walk[name]["start_after"] = handed[i].to_dict()
            if progress:
                progress(i + 1, len(walks), f"ran {name}{again}")
        return maps, per_walk, pooled

    maps, per_walk, pooled = run_all()
    if twice:
        # a second pass: each walk's chain chosen again with the map of the other walks (their
        # first pass; in a split, of the map walks only) as evidence (pipeline/map_prior.py)
        firsts = {n: m["ours"].without_standby() for n, m in maps.items() if n not in asks}
        priors.update(map_priors(firsts, {n: s.wifi for n, s in zip(names, sessions)}, lp, align))
        maps, per_walk, pooled = run_all(" again, with the map of the other walks")
    # the building's walks correct each other, as in merge and a campaign (trust.py)
    truth = {n: s.ground_truth for n, s in zip(names, sessions)}
    map_sig = correct_jointly(maps, per_walk, asks, lp.tau_dbm, bool(align), SAME_WALKS, truth)
    queries = {n: Fingerprints.from_session(s) for n, s in zip(names, sessions)}
    if queries_every > 1:  # a split: every N-th walk by name asks, the others make the map
        queries = {q: f for q, f in queries.items() if q in asks}
        maps = {k: m for k, m in maps.items() if k not in asks}
    covered = {
        q: covered_by_others(qf, [m["tap_oracle"] for k, m in maps.items() if k != q])
        for q, qf in queries.items()
    }
    loo = {kind: score_kind(kind, maps, queries, covered, lp, align) for kind in KINDS}
    matchers = score_matchers(maps, queries, covered, lp, align, loo)
    built = score_built_kinds(maps, queries, covered, lp, align)
    _standby_joined(maps, names, pooled)
    for name in per_walk:
        per_walk[name]["device_offset_db"] = loo["ours"].query_device_offsets_db.get(name)
    sig = np.vstack(pooled.sig_err) if pooled.sig_err else np.empty((0, 2))
    in_map = [w for w in per_walk.values() if not w["quarantine"] and w["reference_points"]]
    return LooResult(
        walks_quarantined=sum(bool(w["quarantine"]) for w in per_walk.values()),
        wrong_start_in_map=sum(not w["start_same_place"] for w in in_map),
        other_start_landmark_in_map=[
            n
            for n, w in per_walk.items()
            if w in in_map and not w["start_right"] and w["start_same_place"]
        ],
        placement_by_kind=_stats_of(pooled.kind_err),
        queries_every=queries_every,
        sigma_check={**sigma_calibration(sig), "held_out": held_out(pooled.sig_terms),
                     "map_points": sigma_calibration(map_sig)},
        verdicts=verdicts(per_walk, asks),
        walks=list(per_walk),
        start=start,
        threshold=base.belief.threshold,
        tau_dbm=lp.tau_dbm,
        align_devices=bool(align),
        tracking=pooled_fix_metrics(pooled.runs),
        tracking_each_walk_alone=alone_metrics,
        per_walk=per_walk,
        loo=loo,
        placement=_stats_of(pooled.placed),
        notes=notes,
        matchers=matchers,
        built_kinds=built,
    )



@dataclass
class _Pooled:
    """What every walk adds to the pooled figures: placement errors by kind of scan and by kind
    of map, (σ, error) of every scan on our trajectories, and the runs."""

    placed: dict[str, list[np.ndarray]] = field(default_factory=lambda: {k: [] for k in PLACEMENT})
    kind_err: dict[str, list[np.ndarray]] = field(default_factory=lambda: {k: [] for k in KINDS})
    sig_err: list[np.ndarray] = field(default_factory=list)
    sig_terms: list[tuple] = field(default_factory=list)  # per walk: σ's terms, the errors
    runs: list[tuple] = field(default_factory=list)
    standby_err: list[np.ndarray] = field(default_factory=list)  # per walk, rows on standby


def _score_walk(r, s, graph: LandmarkGraph, base: Params, shared_with: str | None, pooled: _Pooled):
    """One walk's radio maps of every kind (ours empty when the walk is quarantined), its row of
    the per-walk table, and its placement errors added to ``pooled``."""

    pooled.runs.append((r, s, graph))
    rm, tr, gt = r.radiomap, r.track, s.ground_truth
    assert gt is not None  # checked when the walks were read
    inside = (rm.t >= gt.t[0]) & (rm.t <= gt.t[-1]) & (rm.segment >= 0)
    gx, gy, _ = gt.at(rm.t)
    e = np.hypot(rm.x - gx, rm.y - gy)
    closed = tr.seg_to[np.clip(rm.segment, 0, None)] != ""
    trusted_seg = rm.accepted & ~rm.filled & ~rm.at_landmark
    untrusted = inside & closed & ~rm.at_landmark & ~trusted_seg
    for k, m in (("accepted", rm.accepted), ("trusted_segments", trusted_seg),
                 ("gap_fill", rm.filled), ("at_landmark", rm.at_landmark)):  # fmt: skip
        pooled.placed[k].append(e[inside & m])
    pooled.placed["untrusted_closed"].append(e[untrusted])
    st = graph.node(tr.start_node)
    summ = r.summary(s, graph)
    # a walk whose start its group decided together is no longer ambiguous
    held = [w for w in summ.reasons if not (shared_with is not None and w == "start_ambiguous")]
    trajs = {"tap_oracle": tap_interpolation(s, r.steps.t), "waypoint_pdr": waypoint_pdr(s, base),
             "pdr_i": pdr(s, (st.x, st.y), st.floor, COMPASS_HEADING,
                          known_floors=np.array(graph.floors))}  # fmt: skip
    if rm.sigma is not None:
        pooled.sig_err.append(np.column_stack([rm.sigma[inside], e[inside]]))
        tm = sigma_terms(tr, rm.t[inside], rm.segment[inside], rm.at_landmark[inside])
        if tm is not None:
            pooled.sig_terms.append((tm, e[inside]))
    if not held:
        pooled.kind_err["ours"].append(e[inside & rm.accepted])
        pooled.kind_err["ours_unfiltered"].append(e[inside])
    for k, tj in trajs.items():
        pooled.kind_err[k].append(tj.scan_errors(s))
    for k, of in SAME_WALKS.items():
        pooled.kind_err[k].append(pooled.kind_err[of][-1][:0] if held else pooled.kind_err[of][-1])
    # with the scans held back for their σ on standby: merging settles them (standby.py)
    ours = Fingerprints.from_radiomap(rm, graph.frame, standby=True)
    none = Fingerprints.from_radiomap(rm, graph.frame).subset(slice(0, 0))
    # its rows on standby, placed how well (nan: no truth there), counted if they join
    pooled.standby_err.append(np.where(inside, e, np.nan)[rm.held_for_sigma] if not held else e[:0])
    maps = {  # a quarantined walk's points never go into our maps
        "ours": none if held else ours,
        "ours_unfiltered": none
        if held
        else Fingerprints.from_radiomap(rm, graph.frame, accepted_only=False),  # fmt: skip
        **{k: tj.radio_map(s, graph.frame) for k, tj in trajs.items()},
    }
    maps |= {k: none if held else maps[of] for k, of in SAME_WALKS.items()}
    right = resolve_start("first-fix", s, graph)
    off = _apart(graph, tr.start_node, right) if right else math.inf
    acc_in = inside & rm.accepted  # how far its points are from its own truth: in the map, all
    figures = summ.to_json()
    row = {k: figures.get(k) for k in PER_WALK_KEYS} | {
        "placed_m": round(float(e[acc_in].mean()), 3) if acc_in.any() else None,
        "placed_every_row_m": round(float(e[inside].mean()), 3) if inside.any() else None,
        "start": tr.start_node, "start_right": tr.start_node == right,
        "start_off_m": round(off, 2) if np.isfinite(off) else None,
        "start_same_place": bool(off <= ALTERNATIVE_START_M),
        "start_time_how": tr.start_time_how, "quarantine": held,
    }  # fmt: skip
    if shared_with is not None:
        row["start_shared_with"] = shared_with
    return maps, row


def _standby_joined(maps: dict, names: list[str], pooled: _Pooled) -> None:
    """The placement errors of our rows on standby that join the map of every map walk
    (:mod:`..standby`; leaving one walk out may let a few more join) into ``pooled``: our map's
    placement and the ``standby_joined`` kind."""
    ours = {n: maps[n]["ours"] for n in maps if len(maps[n]["ours"])}
    if not any(m.standby is not None for m in ours.values()):
        return
    # where the rows are is all the rule needs: no RSS merged for it
    x, y, f, wait, sig = (np.concatenate([getattr(m, a) for m in ours.values()])
                          for a in ("x", "y", "floor", "on_standby", "sigma"))  # fmt: skip
    joined = joins(x, y, f, wait, sigma=sig)
    at = 0
    for n, m in ours.items():
        j = joined[at : at + len(m)][m.on_standby]
        at += len(m)
        err = pooled.standby_err[names.index(n)][j]
        err = err[np.isfinite(err)]
        pooled.kind_err["ours"].append(err)
        pooled.placed["standby_joined"].append(err)


def _apart(graph: LandmarkGraph, a: str, b: str) -> float:
    """Metres between two landmarks (inf on different floors)."""
    na, nb = graph.node(a), graph.node(b)
    return math.hypot(na.x - nb.x, na.y - nb.y) if na.floor == nb.floor else math.inf


def _stats_of(parts: dict[str, list[np.ndarray]]) -> dict[str, dict[str, Any]]:
    """Per key, the count and :func:`~workstation.stats.error_stats` of its pooled errors."""
    out = {}
    for k, arrays in parts.items():
        v = np.concatenate(arrays) if arrays else np.empty(0)
        out[k] = {"n": int(v.size)} | error_stats(v)
    return out
