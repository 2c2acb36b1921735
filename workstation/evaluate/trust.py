"""What the walks' verdicts are worth against their own truth (issue #49), and the building's
walks correcting each other inside ``evaluate --walks`` as ``merge`` and a campaign do
(:mod:`workstation.walks.joint`, issue #62)."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, replace

import numpy as np

from workstation.evaluate.scored_walk import KindMaps, ScoredWalk
from workstation.fingerprints.localize import Fingerprints
from workstation.fingerprints.standby import joins
from workstation.session import GroundTruth
from workstation.walks.joint_floors import correct_by_floor

#: a walk "placed wrong" and "placed well" (issue #49: by the mean distance of its points to
#: its own tapped truth)
WRONG_M, GOOD_M = 5.0, 2.0


@dataclass(frozen=True)
class Verdicts:
    """How the walks' verdicts match their truth (:func:`verdicts`; results.json's
    ``verdicts``): the map walks, those in the map, those held out; the ones in the map placed
    more than ``WRONG_M`` off and the held ones placed within ``GOOD_M``; why walks were held."""

    walks: int
    in_map: int
    held: int
    in_map_placed_over_5m: tuple[str, ...]
    held_placed_within_2m: tuple[str, ...]
    held_by_reason: Mapping[str, int]


def correct_jointly(maps: KindMaps, per_walk: dict[str, ScoredWalk], asks: Collection[str],
                    tau: float, align: bool, same_walks: Mapping[str, str],
                    truth: Mapping[str, GroundTruth]) -> np.ndarray:  # fmt: skip
    """The map walks (``maps``: walk → kind → its map; the query walks ``asks`` of a split left
    out) correct each other as ``merge`` and a campaign do (:mod:`workstation.walks.joint`):
    each one's map of ours is replaced by the jointly placed one (σ its marginal); a walk left
    out unreconciled loses its maps of ours (and of the baselines built from the walks in our
    map, ``same_walks``) and gets ``unreconciled`` among its quarantine reasons. Every walk's
    row in ``per_walk`` is replaced by one with ``joint`` (what the estimate did) and its
    ``placed_m`` again
    against its truth (``truth``: walk → ground truth), over the rows the merged map holds (its
    points and the rows on standby that join: :mod:`..fingerprints.standby`). Returns (σ,
    error) of every row the map holds inside the truth's span."""
    mine = {n: m["ours"] for n, m in maps.items() if n not in asks}
    res = correct_by_floor(mine, tau, align)
    held = _held_by_map(res.kept())
    pooled = []
    for n, w in res.walks.items():
        per_walk[n] = replace(per_walk[n], joint=w)  # left out: held for it (ScoredWalk)
        if w.left_out:
            empty = maps[n]["ours"].subset(slice(0, 0))
            maps[n] |= {"ours": empty} | {k: empty for k in same_walks}
            continue
        m = maps[n]["ours"] = res.placed(n)  # (a half left out on standby, not joining)
        if not len(m) or m.t is None:
            continue
        gt = truth[n]
        gx, gy, _ = gt.at(m.t)
        inside = (m.t >= gt.t[0]) & (m.t <= gt.t[-1]) & held[n]
        e = np.hypot(m.x - gx, m.y - gy)
        if inside.any():
            per_walk[n] = replace(per_walk[n], placed_m=round(float(e[inside].mean()), 3))
            sig = m.sigma if m.sigma is not None else np.full(len(m), np.inf)
            pooled.append(np.column_stack([sig, e])[inside])
    return np.vstack(pooled) if pooled else np.empty((0, 2))


def _held_by_map(maps: dict[str, Fingerprints]) -> dict[str, np.ndarray]:
    """Per walk, per row: whether the map merged from ``maps`` holds it (not on standby, or on
    standby and joining as :meth:`Fingerprints.settled` decides over all of them)."""
    live = {n: m for n, m in maps.items() if len(m)}
    out = {n: np.zeros(len(m), bool) for n, m in maps.items()}
    if not live:
        return out
    x, y, f, wait = (np.concatenate([getattr(m, a) for m in live.values()])
                     for a in ("x", "y", "floor", "on_standby"))  # fmt: skip
    sig = np.concatenate([m.sigma if m.sigma is not None else np.full(len(m), np.inf)
                          for m in live.values()])  # fmt: skip
    held = ~wait | joins(x, y, f, wait, sigma=sig)
    at = 0
    for n, m in live.items():
        out[n] = held[at : at + len(m)]
        at += len(m)
    return out


def verdicts(per_walk: dict[str, ScoredWalk], asks: Collection[str] = ()) -> Verdicts:
    """How the walks' verdicts match the truth, over the map walks (``asks``: a split's query
    walks, left out): walks in the map whose points are placed more than ``WRONG_M`` off,
    walks kept out though placed within ``GOOD_M`` (every row, as they would have been
    placed), the reasons."""
    per_walk = {n: w for n, w in per_walk.items() if n not in asks}
    kept = {n: w for n, w in per_walk.items() if w.in_map}
    held = {n: w for n, w in per_walk.items() if w.quarantine}
    wrong = sorted(n for n, w in kept.items() if (w.placed_m or 0) > WRONG_M)
    good = sorted(n for n, w in held.items()
                  if w.placed_every_row_m is not None and w.placed_every_row_m <= GOOD_M)
    return Verdicts(
        len(per_walk), len(kept), len(held), tuple(wrong), tuple(good),
        {r: sum(r in w.quarantine for w in held.values())
         for r in sorted({r for w in held.values() for r in w.quarantine})},
    )  # fmt: skip
