"""What each walk of a leave-one-out adds to its figures (:mod:`.walks`): its radio maps of
every kind, its row of the per-walk table, its placement errors pooled with the others'."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from workstation.baselines.pdr import pdr
from workstation.baselines.tap import tap_interpolation
from workstation.baselines.waypoints import waypoint_pdr
from workstation.evaluate.map_kinds import KINDS, SAME_WALKS
from workstation.evaluate.scored_walk import PER_WALK_KEYS, KindMaps, ScoredWalk
from workstation.fingerprints.localize import Fingerprints
from workstation.fingerprints.standby import joins
from workstation.graph import LandmarkGraph
from workstation.params import COMPASS_HEADING, Params
from workstation.pipeline.confidence import ALTERNATIVE_START_M
from workstation.pipeline.sigma import terms as sigma_terms
from workstation.pipeline.start import resolve_start
from workstation.stats import error_stats

# reference points by how they were placed: every accepted one; those on segments belief trusts;
# every scan of an untrusted closed segment (kept as gap fill or not); the gap fill; the scans
# at landmark stops; the scans held back for their σ that join where no point covers them
PLACEMENT = ("accepted", "trusted_segments", "untrusted_closed", "gap_fill", "at_landmark",
             "standby_joined")  # fmt: skip


@dataclass
class Pooled:
    """What every walk adds to the pooled figures: placement errors by kind of scan and by kind
    of map, (σ, error) of every scan on our trajectories, and the runs."""

    placed: dict[str, list[np.ndarray]] = field(default_factory=lambda: {k: [] for k in PLACEMENT})
    kind_err: dict[str, list[np.ndarray]] = field(default_factory=lambda: {k: [] for k in KINDS})
    sig_err: list[np.ndarray] = field(default_factory=list)
    sig_terms: list[tuple] = field(default_factory=list)  # per walk: σ's terms, the errors
    runs: list[tuple] = field(default_factory=list)
    standby_err: list[np.ndarray] = field(default_factory=list)  # per walk, rows on standby
    standby_t: list[np.ndarray] = field(default_factory=list)  # … and their times


def score_walk(r, s, graph: LandmarkGraph, base: Params, shared_with: str | None, pooled: Pooled):
    """One walk's radio maps of every kind (ours empty when the walk is quarantined), its row of
    the per-walk table, and its placement errors added to ``pooled``."""

    pooled.runs.append((r, s, graph))
    rm, tr = r.radiomap, r.track
    inside, e = _placed(r, s, pooled)
    st = graph.node(tr.start.node)
    summ = r.summary(s, graph)
    # a walk whose start its group decided together is no longer ambiguous
    held = [w for w in summ.reasons if not (shared_with is not None and w == "start_ambiguous")]
    trajs = {"tap_oracle": tap_interpolation(s, r.steps.t), "waypoint_pdr": waypoint_pdr(s, base),
             "pdr_i": pdr(s, (st.x, st.y), st.floor, COMPASS_HEADING,
                          known_floors=np.array(graph.floors))}  # fmt: skip
    if rm.sigma is not None:
        pooled.sig_err.append(np.column_stack([rm.sigma[inside], e[inside]]))
        tm = sigma_terms(tr, rm.t[inside], rm.segment[inside], rm.at_landmark[inside], r.heading)
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
    pooled.standby_t.append(rm.t[rm.held_for_sigma] if not held else rm.t[:0])
    maps = {  # a quarantined walk's points never go into our maps
        "ours": none if held else ours,
        "ours_unfiltered": none
        if held
        else Fingerprints.from_radiomap(rm, graph.frame, accepted_only=False),  # fmt: skip
        **{k: tj.radio_map(s, graph.frame) for k, tj in trajs.items()},
    }
    maps |= {k: none if held else maps[of] for k, of in SAME_WALKS.items()}
    return maps, _row(r, s, graph, summ, inside, e, tuple(held), shared_with)


def _placed(r, s, pooled: Pooled) -> tuple[np.ndarray, np.ndarray]:
    """Which of the walk's scans lie within its ground truth's time span (on a segment), and
    each scan's placement error; the errors pooled by how the scans were placed."""
    rm, tr, gt = r.radiomap, r.track, s.ground_truth
    assert gt is not None  # checked when the walks were read
    inside = (rm.t >= gt.t[0]) & (rm.t <= gt.t[-1]) & (rm.segment >= 0)
    gx, gy, _ = gt.at(rm.t)
    e = np.hypot(rm.x - gx, rm.y - gy)
    closed = tr.segments.to_node[np.clip(rm.segment, 0, None)] != ""
    trusted_seg = rm.accepted & ~rm.filled & ~rm.at_landmark
    untrusted = inside & closed & ~rm.at_landmark & ~trusted_seg
    for k, m in (("accepted", rm.accepted), ("trusted_segments", trusted_seg),
                 ("gap_fill", rm.filled), ("at_landmark", rm.at_landmark)):  # fmt: skip
        pooled.placed[k].append(e[inside & m])
    pooled.placed["untrusted_closed"].append(e[untrusted])
    return inside, e


def _row(r, s, graph: LandmarkGraph, summ, inside: np.ndarray, e: np.ndarray,
         held: tuple[str, ...], shared_with: str | None) -> ScoredWalk:  # fmt: skip
    """The walk's row of the per-walk table: its run's figures, how far its points lie from its
    own truth (in the map, all) and whether it started where its first fix says."""
    rm, tr = r.radiomap, r.track
    right = resolve_start("first-fix", s, graph)
    off = _apart(graph, tr.start.node, right) if right else math.inf
    acc_in = inside & rm.accepted
    figures = summ.to_json()
    return ScoredWalk(
        {k: figures.get(k) for k in PER_WALK_KEYS},
        placed_m=round(float(e[acc_in].mean()), 3) if acc_in.any() else None,
        placed_every_row_m=round(float(e[inside].mean()), 3) if inside.any() else None,
        start=tr.start.node, start_right=tr.start.node == right,
        start_off_m=round(off, 2) if np.isfinite(off) else None,
        start_same_place=bool(off <= ALTERNATIVE_START_M),
        start_time_how=tr.start.time_how, reasons=held, start_shared_with=shared_with,
    )  # fmt: skip


def standby_joined(maps: KindMaps, names: list[str], pooled: Pooled) -> None:
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
        j = _held_joining(m, joined[at : at + len(m)], pooled.standby_t[names.index(n)])
        at += len(m)
        err = pooled.standby_err[names.index(n)][j]
        err = err[np.isfinite(err)]
        pooled.kind_err["ours"].append(err)
        pooled.placed["standby_joined"].append(err)


def _held_joining(m: Fingerprints, joined: np.ndarray, held_t: np.ndarray) -> np.ndarray:
    """Per row its σ held back (at times ``held_t``), whether it joins (``joined``: per row of
    ``m``). A half of the walk the joint estimate left out is on standby too, never joining
    (walks/joint.py): then the rows are found by their times."""
    wait = m.on_standby
    if m.t is None or int(wait.sum()) == held_t.size:
        return joined[wait]
    order = np.argsort(held_t, kind="stable")
    k = np.searchsorted(held_t[order], m.t[wait])
    ok = k < held_t.size
    ok[ok] = held_t[order][k[ok]] == m.t[wait][ok]
    out = np.zeros(held_t.size, bool)
    out[order[k[ok]]] = joined[wait][ok]
    return out


def _apart(graph: LandmarkGraph, a: str, b: str) -> float:
    """Metres between two landmarks (inf on different floors)."""
    na, nb = graph.node(a), graph.node(b)
    return math.hypot(na.x - nb.x, na.y - nb.y) if na.floor == nb.floor else math.inf


def stats_of(parts: dict[str, list[np.ndarray]]) -> dict[str, dict[str, float]]:
    """Per key, the count and :func:`~workstation.stats.error_stats` of its pooled errors."""
    out: dict[str, dict[str, float]] = {}
    for k, arrays in parts.items():
        v = np.concatenate(arrays) if arrays else np.empty(0)
        out[k] = {"n": int(v.size)} | error_stats(v)
    return out
