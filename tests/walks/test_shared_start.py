"""Walks that stood at one place decide their start together (pipeline/shared_start.py): the
stand fingerprint, mutual nearest neighbours, and the summed loss over common candidates, on
hand-made scans and tracks where the answer is known."""

from types import SimpleNamespace

import numpy as np
import pytest

from workstation.pipeline.tracking.state import Start
from workstation.session.model import WifiScans
from workstation.walks.shared_start import (
    shared_starts,
    stand_distances,
    stand_fingerprint,
    stand_groups,
)

APS = np.array([f"ap{i:02d}" for i in range(12)])


def _field(spot: int, rng) -> np.ndarray:
    """Mean RSS of the 12 APs at one of a few spots (each spot its own loud APs)."""
    base = np.full(APS.size, -85.0)
    base[spot * 3 : spot * 3 + 3] = [-45.0, -55.0, -62.0]
    return base + rng.normal(0, 1.5, APS.size)


def _walk(spot: int, offset_db: float, seed: int, stand_s=20.0, scan_s=2.0):
    """Scans every ``scan_s`` at the spot during the stand, then elsewhere (spot 3)."""
    rng = np.random.default_rng(seed)
    where = {s: _field(s, np.random.default_rng(100 + s)) for s in range(4)}
    t, b, r = [], [], []
    for ts in np.arange(0.5, stand_s + 30.0, scan_s):
        mean = where[spot] if ts < stand_s else where[3]
        rss = mean + offset_db + rng.normal(0, 2.0, APS.size)
        keep = rss > -92
        t += [ts] * int(keep.sum())
        b += list(APS[keep])
        r += list(np.round(rss[keep]))
    t = np.array(t)
    return WifiScans(t, np.array(b), np.array(b), np.full(t.size, 2412.0), np.array(r))


def _track(cands, start_time=20.0):
    return SimpleNamespace(start=Start(node=cands[0][0], time=start_time,
                                       candidates=tuple(cands)))  # fmt: skip


def test_stand_fingerprint_is_the_stand_only():
    w = _walk(0, 0.0, 1)
    bssids, mean = stand_fingerprint(w, 20.0)
    loud = dict(zip(bssids, mean))
    assert loud["ap00"] == pytest.approx(-45, abs=3) and "ap09" in loud
    assert loud["ap09"] < -75  # spot 3's loud AP is only heard after the stand
    assert stand_fingerprint(w, 1.0) is None  # one scan is not a stand


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_walks_from_one_spot_are_mutual_nearest_whatever_the_phone(seed):
    """Two walks from spot 0 (phones 7 dB apart), one each from spots 1 and 2."""
    walks = [_walk(0, 0.0, seed), _walk(1, 0.0, seed + 10), _walk(0, 7.0, seed + 20),
             _walk(2, -3.0, seed + 30)]  # fmt: skip
    d = stand_distances([stand_fingerprint(w, 20.0) for w in walks])
    assert stand_groups(d) == [(0, 2)]
    assert d[0, 2] < 0.5 * min(d[0, 1], d[0, 3], d[2, 1], d[2, 3])


def test_the_group_takes_the_start_that_loses_least_in_total():
    """Walk 0 alone prefers C (B 0.6 behind); walk 1 prefers B (C 1.9 behind): together B.
    Walk 2 from elsewhere keeps its own start."""
    walks = [_walk(0, 0.0, 1), _walk(0, 5.0, 2), _walk(1, 0.0, 3)]
    tracks = [
        _track([("C", 0.0), ("B", 0.6), ("D", 0.7)]),
        _track([("B", 0.0), ("C", 1.9), ("E", 4.0)]),
        _track([("F", 0.0), ("B", 0.5)]),
    ]
    (g,) = shared_starts(walks, tracks)
    assert g.walks == (0, 1) and g.start == "B"
    assert g.totals == {"B": 0.6, "C": 1.9}


def test_no_shared_decision_without_ambiguity_or_common_candidates():
    walks = [_walk(0, 0.0, 1), _walk(0, 5.0, 2)]
    sure = [_track([("C", 0.0), ("B", 4.0)]), _track([("B", 0.0), ("C", 3.5)])]
    assert shared_starts(walks, sure) == []  # neither walk is ambiguous: each keeps its own
    apart = [_track([("C", 0.0), ("D", 0.6)]), _track([("B", 0.0), ("E", 1.0)])]
    assert shared_starts(walks, apart) == []
    given = [
        _track([("C", 0.0), ("B", 0.6)]),
        SimpleNamespace(start=Start(node="C", time=20.0)),
    ]
    assert shared_starts(walks, given) == []  # a given start takes no part


def test_a_group_decides_only_on_complete_agreeing_evidence():
    """Walk 1's own best (E) is not among walk 0's candidates: its loss there is unknown, no
    decision. A start that would cost some walk 3 or more (it is sure of another): the walks
    did not stand together, no decision either. Otherwise the least total wins, also when it
    moves the walk that was ambiguous towards the one that was not."""
    walks = [_walk(0, 0.0, 1), _walk(0, 5.0, 2)]
    unknown = [_track([("C", 0.0), ("B", 0.6)]), _track([("E", 0.0), ("B", 0.1), ("C", 0.2)])]
    assert shared_starts(walks, unknown) == []
    veto = [
        _track([("C", 0.0), ("X", 1.0), ("B", 3.2)]),
        _track([("B", 0.0), ("C", 3.3), ("X", 3.5)]),
    ]
    assert shared_starts(walks, veto) == []  # B totals 3.2, all of it walk 0's
    compromise = [_track([("C", 0.0), ("X", 1.0), ("B", 3.2)]),
                  _track([("B", 0.0), ("X", 2.0), ("C", 3.3)])]  # fmt: skip
    (g,) = shared_starts(walks, compromise)
    assert g.start == "X" and g.totals == {"B": 3.2, "C": 3.3, "X": 3.0}
    one_sure = [_track([("C", 0.0), ("B", 3.2)]), _track([("B", 0.0), ("C", 1.0)])]
    (g,) = shared_starts(walks, one_sure)
    assert g.start == "C"  # walk 1 (ambiguous) moves to walk 0's start; walk 0 keeps it


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_simulated_walks_from_one_landmark_stand_together(seed):
    """Simulated office, realistic radio (phones several dB apart, drifting RSS): the normal
    and the varied walk both start at W0, the held-out walk at SW0 (the simulator's routes).
    Only the two from W0 are each other's nearest stand fingerprint."""
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.sim import simulate
    from workstation.sim.building import office2f

    b = office2f()
    sims = [simulate(b, "normal", seed, "realistic"), simulate(b, "varied", seed + 100, "realistic"),
            simulate(b, "heldout", seed + 200, "realistic")]  # fmt: skip
    from workstation.pipeline.start import resolve_start

    truth = [resolve_start("first-fix", sim.session, b.graph) for sim in sims]
    assert truth == ["W0", "W0", "SW0"]
    prints = []
    for sim in sims:
        tr = Pipeline(sim.session, b.graph, Params()).run().track
        prints.append(stand_fingerprint(sim.session.wifi, tr.start.time))
    d = stand_distances(prints)
    assert stand_groups(d) == [(0, 1)]
    assert d[0, 1] < 0.6 * min(d[0, 2], d[1, 2])
