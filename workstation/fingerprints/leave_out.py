"""Each walk localized on the map of the building's other walks — a campaign's leave-one-walk-out
figure — with one index for every walk (issue #66: merging the others anew for each walk grew
as W²: 314 walks, 58 of the report's 64 s).

The walks' maps are merged once (device offsets fitted once, over all of them: with many walks
one walk moves them little) and indexed once; each walk's own rows are then left out of the
search (:meth:`.localize.RadioMapIndex.localize_without`) and the access points only its map
lists dropped from its queries, as the others' map would not list them. Its queries' device
offset is measured against the whole map. At most ``MAX_WALKS`` walks ask (every n-th): the
figure is a statistic, its cost then bounded however many walks the building has.
"""

from __future__ import annotations

import numpy as np

from workstation.fingerprints.devices import ap_means, offset_against, one_model
from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
from workstation.fingerprints.matchers import Matcher

MAX_WALKS = 200  # walks asked at most (every n-th of those with queries)


def every_nth(keys: list[str], max_walks: int = MAX_WALKS) -> list[str]:
    """At most ``max_walks`` of ``keys``: every n-th, from the first."""
    return keys[:: max(1, -(-len(keys) // max_walks))]


def leave_one_walk_out(
    maps: dict[str, Fingerprints],
    queries: dict[str, Fingerprints],
    matcher: Matcher,
    tau: float = -90.0,
    max_walks: int = MAX_WALKS,
) -> tuple[np.ndarray, np.ndarray, int]:
    """(horizontal errors, floor errors, walks asked): the queries of each walk of ``queries``
    (its scans at their truth) localized with ``matcher`` on the map of the walks of ``maps``
    but its own (a walk without a map asks the whole map)."""
    live = {k: m.settled() for k, m in maps.items() if len(m)}
    asking = every_nth([k for k, q in queries.items() if len(q)], max_walks)
    empty = (np.empty(0), np.empty(0), 0)
    if len(live) < 2 or not asking:
        return empty
    names = list(live)
    merged = Fingerprints.merge(list(live.values()), align_devices=True, settle=False)
    stop = np.cumsum([len(live[k]) for k in names])
    start = stop - [len(live[k]) for k in names]
    index = RadioMapIndex(merged, tau, representation=matcher.representation)
    member = np.zeros((len(names), merged.bssids.size), bool)  # the APs each map lists
    for i, k in enumerate(names):
        member[i, np.searchsorted(merged.bssids, live[k].bssids)] = True
    count = member.sum(axis=0)
    means = ap_means(merged.rss)
    err, ferr = [], []
    row_of = {k: i for i, k in enumerate(names)}
    for k in asking:
        q = queries[k]
        i = row_of.get(k, -1)
        lo, hi = (int(start[i]), int(stop[i])) if i >= 0 else (0, 0)
        if hi - lo >= len(merged):
            continue
        columns = count - member[i] > 0 if i >= 0 else count > 0
        if not one_model([merged.device, q.device]):
            q = q.shifted(-offset_against(means, ap_means(q.aligned(merged.bssids))))
        est = index.localize_without(q, matcher.k, lo, hi, matcher.metric, matcher.weights,
                                     columns)  # fmt: skip
        err.append(np.hypot(est.x - q.x, est.y - q.y))
        ferr.append(est.floor - q.floor)
    if not err:
        return empty
    return np.concatenate(err), np.concatenate(ferr), len(err)
