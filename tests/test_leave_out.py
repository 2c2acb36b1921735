"""A campaign's leave-one-walk-out with one index for every walk (fingerprints/leave_out.py,
issue #66) gives what merging the other walks anew for each one gives (phones of one model, the
same weakest reading), over several seeds; and asks at most ``max_walks`` walks."""

import numpy as np
import pytest

from workstation.fingerprints.leave_out import leave_one_walk_out
from workstation.fingerprints.localize import Fingerprints, localize
from workstation.fingerprints.matchers import METHODS


def _maps(rng, n_walks: int, aps: int = 12):
    """Walks along one corridor, each with its map and its queries (scans at their truth); one
    reading of −99 dBm in every map (the same weakest reading, as the others' maps have)."""
    names = np.array([f"ap{i}" for i in range(aps)])
    src = rng.uniform(0, 80, aps)
    maps, queries = {}, {}
    for w in range(n_walks):
        def scans(n):
            x = rng.uniform(0, 80, n)
            rss = -40 - 0.6 * np.abs(x[:, None] - src[None]) + rng.normal(0, 3, (n, aps))
            return x, np.where(rss > -90, rss, np.nan)

        x, rss = scans(30)
        rss[0, 0] = -99.0
        own = names[rng.random(aps) < 0.9]  # a walk may not list every AP
        cols = np.isin(names, own)
        maps[f"w{w}"] = Fingerprints(x, np.zeros(30), np.zeros(30), own, rss[:, cols],
                                     device="P1", sigma=np.full(30, 1.0))  # fmt: skip
        qx, qr = scans(10)
        queries[f"w{w}"] = Fingerprints(qx, np.zeros(10), np.zeros(10), names, qr, device="P1")
    return maps, queries


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("method", ["1nn", "powed-sorensen-5nn"])
def test_one_index_gives_what_merging_the_others_gives(seed, method):
    rng = np.random.default_rng(seed)
    maps, queries = _maps(rng, 6)
    m = METHODS[method]
    err, ferr, asked = leave_one_walk_out(maps, queries, m, tau=-90.0)
    want = []
    for k, q in queries.items():
        others = Fingerprints.merge([v for kk, v in maps.items() if kk != k], align_devices=True)
        est = localize(others, q, tau=-90.0, align_device=False, matcher=m)  # one model
        want.append(np.hypot(est.x - q.x, est.y - q.y))
    assert asked == 6 and np.allclose(err, np.concatenate(want)) and not ferr.any()


def test_at_most_max_walks_ask_and_a_walk_without_a_map_asks_the_whole_map():
    rng = np.random.default_rng(9)
    maps, queries = _maps(rng, 10)
    assert leave_one_walk_out(maps, queries, METHODS["1nn"], max_walks=3)[2] == 3
    queries["new"] = queries["w0"]  # a walk with no map of its own (quarantined)
    err, _, asked = leave_one_walk_out(maps, {"new": queries["new"]}, METHODS["1nn"])
    assert asked == 1 and err.size == len(queries["new"])
    assert leave_one_walk_out({"w0": maps["w0"]}, queries, METHODS["1nn"])[2] == 0  # one map
