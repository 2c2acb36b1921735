"""Walks that begin at one place decide their start together (beyond the paper).

A walk's start is inferred from its own sensors (``pdr.start_node`` unset): every landmark is
tried and the chain that best explains the walk wins. A short walk along one of several
parallel corridors can hold too little to tell them apart — the museum's Trial21 rep01 walks
22 m out and back; three corridors fit its turns and compass within 4°, and its steps are
too long for the default step length, so the wrong corridor wins by 0.64 (log-likelihood).

A surveyor seldom walks once. Walks that stood at the same spot before setting off hear the
same access points there: their initial stands' fingerprints are each other's nearest among
the walks. Such walks share a start, and for a shared start the evidence of the walks adds up:
the joint log-likelihood of a start is the sum of each walk's. So:

1. each walk's *stand fingerprint*: the mean RSS per AP over its scans before the walk starts
   (APs under τ unheard), compared as 1-NN compares scans (positive representation, eq. 21)
   after removing the two phones' offset (median difference over the APs both heard);
2. walks that are each other's nearest stand fingerprint (mutual nearest neighbours, no
   threshold) are joined, and joined groups merged;
3. in a group where some walk's inferred start is ambiguous (a start elsewhere within
   ``START_AMBIGUOUS_MARGIN``), the start is the one among every walk's candidate starts that
   loses least in total; the walks whose own best differs are re-run from it.

Mutual nearest neighbours always pair someone (the closest two of any set of walks), and WiFi
tells places a few metres apart only weakly (on the museum the stands at L18, floor 0, and L31,
two floors below and 4 m away, are 4.6 apart against 3.0–3.9 for walks from one landmark).
So a group decides only when its evidence is complete and agrees with every walk's own: each
walk's own best start is among every other walk's candidates (otherwise its loss there is
unknown), and no walk loses ``START_AMBIGUOUS_MARGIN`` or more at the chosen start (a walk
sure of another start did not stand with the others). Walks whose starts were given take no
part; a group that does not decide keeps each walk's own start.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline, Result
from workstation.pipeline.tracking.state import START_AMBIGUOUS_MARGIN
from workstation.session import Session, WifiScans
from workstation.walks.chain import Handover, hand_over

MIN_STAND_SCANS = 2


@dataclass(frozen=True)
class SharedStart:
    """One group of walks that stood at one place: the walks (indices), the start chosen, and
    each candidate's total loss (log-likelihood below each walk's own best, summed)."""

    walks: tuple[int, ...]
    start: str
    totals: dict[str, float]


def stand_fingerprint(
    wifi: WifiScans, start_time: float, tau: float = -90.0
) -> tuple[np.ndarray, np.ndarray] | None:
    """(bssids, mean dBm per AP, NaN unheard) over the scans before ``start_time``, or None."""
    times, bssids, rss = wifi.matrix()
    m = times < start_time
    if m.sum() < MIN_STAND_SCANS:
        return None
    r = np.where(rss[m] >= tau, rss[m], np.nan)
    heard = ~np.isnan(r).all(axis=0)
    if not heard.any():
        return None
    return bssids[heard], np.nanmean(r[:, heard], axis=0)


def stand_distances(prints: list, tau: float = -90.0) -> np.ndarray:
    """Pairwise distances of stand fingerprints (inf where either walk has none)."""
    n = len(prints)
    d = np.full((n, n), np.inf)
    for i in range(n):
        for j in range(i + 1, n):
            if prints[i] is None or prints[j] is None:
                continue
            d[i, j] = d[j, i] = _distance(prints[i], prints[j], tau)
    return d


def _distance(
    a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], tau: float
) -> float:
    ids = np.union1d(a[0], b[0])
    va, vb = np.full(ids.size, np.nan), np.full(ids.size, np.nan)
    va[np.searchsorted(ids, a[0])] = a[1]
    vb[np.searchsorted(ids, b[0])] = b[1]
    both = ~np.isnan(va) & ~np.isnan(vb)
    if not both.any():
        return float("inf")
    off = float(np.median(va[both] - vb[both]))
    pa = np.nan_to_num(va - off / 2 - (tau - 1), nan=0.0).clip(0)
    pb = np.nan_to_num(vb + off / 2 - (tau - 1), nan=0.0).clip(0)
    return float(np.sqrt(np.mean((pa - pb) ** 2)))


def stand_groups(d: np.ndarray) -> list[tuple[int, ...]]:
    """Groups (of two walks or more) joined by mutual nearest stand fingerprints."""
    n = d.shape[0]
    parent = list(range(n))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if n >= 2:
        nearest = np.argmin(d, axis=1)
        for i in range(n):
            j = int(nearest[i])
            if np.isfinite(d[i, j]) and int(nearest[j]) == i:
                parent[root(i)] = root(j)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(root(i), []).append(i)
    return [tuple(g) for g in groups.values() if len(g) > 1]


def shared_starts(wifis: list, tracks: list, tau: float = -90.0) -> list[SharedStart]:
    """The groups of walks whose start is decided together (see the module doc). ``tracks``
    are the walks' tracks with their starts inferred (``Track.start.candidates``); a track
    whose start was given (no candidates) takes no part."""
    prints = [
        stand_fingerprint(w, tr.start.time, tau) if tr.start.candidates else None
        for w, tr in zip(wifis, tracks)
    ]
    return decide_shared(prints, [tuple(tr.start.candidates) for tr in tracks], tau)


def decide_shared(prints: list, candidates: list, tau: float = -90.0) -> list[SharedStart]:
    """:func:`shared_starts` from the walks' stand fingerprints (None: no stand, or the start
    was given) and candidate starts ((node, loss), best first)."""
    out = []
    for g in stand_groups(stand_distances(prints, tau)):
        if not any(len(candidates[i]) > 1 and candidates[i][1][1] < START_AMBIGUOUS_MARGIN
                   for i in g):  # fmt: skip
            continue
        cands = [dict(candidates[i]) for i in g]
        bests = {candidates[i][0][0] for i in g}
        if not all(b in c for b in bests for c in cands):
            continue  # some walk's own best has no known loss for another: no comparison
        common = set(cands[0]).intersection(*cands[1:])
        totals = {n: round(sum(c[n] for c in cands), 2) for n in sorted(common)}
        start = min(totals, key=totals.__getitem__)
        if any(c[start] >= START_AMBIGUOUS_MARGIN for c in cands):
            continue  # a walk sure of another start: these walks did not stand together
        out.append(SharedStart(g, start, totals))
    return out


def run_inferring_starts(
    sessions: list[Session], graph: LandmarkGraph, params: Params,
    alone: list[Result] | None = None, given: Collection[int] = frozenset(),
    names: Sequence[str] | None = None,
) -> tuple[list[Result], list[SharedStart], dict[int, Handover]]:  # fmt: skip
    """Every walk run with its start inferred (or ``alone``: those runs, already made; the walks
    in ``given``, by index, with their start given), then the walks of each
    :func:`shared_starts` group whose own best start differs re-run from the group's start, then
    each ambiguous walk that follows a certain one searched within reach of where that one
    ended (:func:`.chain.hand_over`). Returns the results (in order), the groups and the
    handovers (by walk index)."""

    p = params.updated(**{"pdr.start_node": None})
    results = list(alone) if alone is not None else [Pipeline(s, graph, p).run() for s in sessions]
    groups = shared_starts([s.wifi for s in sessions], [r.track for r in results],
                           params.localize.tau_dbm)  # fmt: skip
    for g in groups:
        for i in g.walks:
            if results[i].track.start.node != g.start:
                fixed = params.updated(**{"pdr.start_node": g.start})
                results[i] = Pipeline(sessions[i], graph, fixed).run()
    handed = hand_over(sessions, graph, params, results, given, names)
    return results, groups, handed
