"""The joint estimate (:mod:`.joint`) floor by floor: links only join scans of one floor, so
a building's floors are independent problems — each can run on its own worker (a campaign's
Dask cluster), and a building of many floors never becomes one large system.

A walk that crosses floors (stairs, a lift) is corrected on each floor apart; its parts are put
back together in the walk's row order: its points, their σ, and one account of what was done to
it (rows and links summed, the shift averaged over its rows, the largest shift and
disagreement of any part; left out when a part is)."""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterable
from dataclasses import replace

import numpy as np

from workstation.fingerprints.localize import Fingerprints
from workstation.walks.joint import JointResult, WalkCorrection, correct

Runner = Callable[[Callable, list[tuple]], Iterable]


def _local(fn: Callable, args: list[tuple]) -> Iterable:
    return (fn(*a) for a in args)


def correct_by_floor(
    maps: dict[str, Fingerprints], tau: float = -90.0, align: bool = True,
    fixed: Collection[str] = (), run: Runner | None = None,
) -> JointResult:  # fmt: skip
    """:func:`.joint.correct` on each floor's rows of ``maps``, by ``run`` (fn, [args, …]) →
    results in order: here, one after another, unless given (a campaign's workers)."""
    names = list(maps)
    floors = sorted({float(f) for m in maps.values() for f in np.unique(m.floor)})
    if len(floors) <= 1:
        return correct(maps, tau, align, fixed)
    parts, rows = [], []
    for f in floors:
        on = {n: np.flatnonzero(maps[n].floor == f) for n in names}
        part = {n: maps[n].subset(on[n]) for n in names if on[n].size}
        parts.append((part, tau, align, tuple(n for n in fixed if n in part)))
        rows.append({n: on[n] for n in part})
    results = list((run or _local)(correct, parts))
    return _stitch(maps, names, results, rows)


def _stitch(maps: dict[str, Fingerprints], names: list[str], results: list[JointResult],
           rows: list[dict]) -> JointResult:  # fmt: skip
    out: dict[str, Fingerprints] = {}
    for n in names:
        m = maps[n]
        x, y = m.x.copy(), m.y.copy()
        sig = (m.sigma.copy() if m.sigma is not None else np.full(len(m), np.inf))
        for res, on in zip(results, rows):
            if n in on:
                p = res.maps[n]
                x[on[n]], y[on[n]] = p.x, p.y
                if p.sigma is not None:
                    sig[on[n]] = p.sigma
        out[n] = replace(m, x=x, y=y, sigma=sig)
    walks = {n: _combine(n, [res.walks[n] for res in results if n in res.walks]) for n in names}
    first = dict(zip(names, np.concatenate([[0], np.cumsum([len(maps[n]) for n in names])])))
    links = []
    for res, on in zip(results, rows):
        if not len(res.links):
            continue
        part_names = [n for n in res.maps if len(res.maps[n])]
        glob = np.concatenate([first[n] + on[n] for n in part_names])  # part row → walk row
        ln = res.links.copy()
        ln[:, 0], ln[:, 1] = glob[ln[:, 0].astype(int)], glob[ln[:, 1].astype(int)]
        links.append(ln)
    return JointResult(out, walks, np.vstack(links) if links else np.empty((0, 3)))


def _combine(name: str, parts: list[WalkCorrection]) -> WalkCorrection:
    """One walk's account from its floors' (module doc)."""
    if len(parts) == 1:
        return parts[0]
    rows = sum(p.rows for p in parts)
    links = sum(p.links for p in parts)
    most = max(parts, key=lambda p: p.shift_max_m)
    worst = max(parts, key=lambda p: (p.unreconciled, p.disagree_m))
    # the half a floor left out (its times hold on the whole walk), else the worst floor's
    half = next((p for p in parts if p.part_out), worst)
    return WalkCorrection(
        name, rows, links,
        sum(p.shift_mean_m * p.rows for p in parts) / max(rows, 1), most.shift_max_m, most.where,
        worst.disagree_m, sum(p.covered * p.rows for p in parts) / max(rows, 1),
        worst.agree, any(p.left_out for p in parts), half.part, half.part_s, half.part_out,
    )  # fmt: skip
