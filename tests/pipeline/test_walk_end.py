"""The walk ends on a landmark (pipeline/walk_end.py): on hand-made tracks where the answer is
known, and on ten real mall walks (tests/data/msilc, MIT) whose last tap is where they end."""

import math

import numpy as np
import pytest

from tests.conftest import REPO
from workstation import pipeline
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.confidence import open_sigma
from workstation.pipeline.landmarks import Detections
from workstation.pipeline.sigma import (
    BASE_M,
    DRIFT,
    SCALE,
    placement_sigma,
)
from workstation.pipeline.start import resolve_start
from workstation.pipeline.tracking.state import END_CHECK_M, Segments, Start, Steps, Track
from workstation.pipeline.tracking.state import Detections as TrackDetections
from workstation.pipeline.tracking.walk_end import end_on_landmark
from workstation.session import load_session

DATA = REPO / "tests" / "data" / "msilc"
SHORT = REPO / "tests" / "data" / "msilc-short"


def _east(n_steps: int, length: float = 0.7, seg_to: str = "") -> Track:
    """One segment from A at the origin, ``n_steps`` steps due east."""
    t = np.arange(1, n_steps + 1, dtype=float)
    x = t * length
    z = np.zeros(n_steps)
    return Track(
        Steps(t=t, x=x, y=z, floor=z, heading=z, step_length=z + length,
              segment=np.zeros(n_steps, int), x_bc=x.copy(), y_bc=z.copy(), raw_x=x.copy(),
              raw_y=z.copy()),
        TrackDetections(node=np.array([], str), confidence=z[:0], candidate=np.array([], str),
                        reason=np.array([], str), spread=z[:0]),
        Segments(from_node=np.array(["A"]), to_node=np.array([seg_to]), t0=np.array([0.0]),
                 t1=np.array([t[-1]]), missed=np.zeros(1, np.int64)),
        Start(node="A", time=0.0),
    )  # fmt: skip


def test_an_open_end_near_one_landmark_is_closed_on_it():
    tr = _east(10)  # ends at (7, 0); σ = hypot(0.5, 0.2 · 7) = 1.49 m
    pos = {"A": (0.0, 0.0, 0.0), "B": (7.5, 0.4, 0.0), "C": (20.0, 0.0, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end.node == "B" and out.end.how == "closed"
    assert out.segments.to_node.tolist() == ["B"]
    assert (out.steps.x_bc[-1], out.steps.y_bc[-1]) == pytest.approx((7.5, 0.4))
    assert np.array_equal(out.steps.x, tr.steps.x) and np.array_equal(out.steps.y, tr.steps.y)  # forward untouched
    # the likeliest place elsewhere (> 5 m from B) is A, 7 m behind, against B 0.64 m off
    sd = open_sigma(0.0, 7.0)
    assert out.end.margin == pytest.approx(0.5 * (7.0**2 - 0.5**2 - 0.4**2) / sd**2, rel=0.02)
    # the segment is closed now: σ falls towards its end instead of growing
    sig = placement_sigma(out, out.steps.t, out.steps.segment, np.zeros(out.steps.t.size, bool))
    assert sig[-1] == pytest.approx(SCALE * BASE_M, abs=0.05)
    assert sig[-1] < placement_sigma(tr, tr.steps.t, tr.steps.segment, np.zeros(tr.steps.t.size, bool))[-1]


def test_two_places_nearly_as_likely_leave_the_end_open():
    tr = _east(40)  # 28 m: σ = hypot(0.5, 5.6) = 5.6 m; B1 and B2 are 12 m apart (> 2σ), 6 m off
    pos = {"A": (0.0, 0.0, 0.0), "B1": (28.0, 6.0, 0.0), "B2": (28.0, -6.0, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end.node == "" and out.segments.to_node.tolist() == [""] and out.end.how == "ambiguous"
    assert out.end.margin == pytest.approx(0.0, abs=1e-6)
    assert np.array_equal(out.steps.x_bc, tr.steps.x_bc)


def test_places_nearer_than_twice_the_ends_sigma_are_one_place():
    """σ 5.6 m: landmarks 6 m apart, 3 m either side of the end, are one place at that σ (it
    cannot tell them apart): the end closes on one of them, the other 6 m away its spread —
    an end that sure checks no walk (σ over END_CHECK_M), and its scans are no surer than the
    walk from A makes them (σ from the nearer anchor: the spread of 6 m is worse)."""
    tr = _east(40)
    pos = {"A": (0.0, 0.0, 0.0), "B1": (28.0, 3.0, 0.0), "B2": (28.0, -3.0, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end.how == "closed" and out.end.node in ("B1", "B2")
    assert out.end.spread == pytest.approx(6.0) and out.end.sigma == pytest.approx(5.62, abs=0.05)
    sig = placement_sigma(out, out.steps.t, out.steps.segment, np.zeros(out.steps.t.size, bool))
    before = placement_sigma(tr, tr.steps.t, tr.steps.segment, np.zeros(tr.steps.t.size, bool))
    # a loose end anchors no better than its own σ (issue #49): near it, σ is at least that
    # σ's or the walk from A's, whichever is smaller
    assert sig[-1] >= SCALE * min(out.end.sigma, DRIFT * 27.0) - 1e-9 and sig[-1] < before[-1]


def test_landmarks_a_metre_or_two_apart_are_one_place_and_its_spread_is_kept():
    """… and an end closed that loosely (σ 5.6 m, over END_CHECK_M) anchors no better than that
    σ (issue #49: no 0.5-m landmark at the end of 28 m of drift)."""
    tr = _east(40)
    pos = {"A": (0.0, 0.0, 0.0), "B1": (28.0, 1.0, 0.0), "B2": (28.0, -1.5, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end.node == "B1"
    assert out.end.spread == pytest.approx(2.5)
    sig = placement_sigma(out, out.steps.t, out.steps.segment, np.zeros(out.steps.t.size, bool))
    assert sig[-1] >= SCALE * min(out.end.sigma, DRIFT * 27.0) - 1e-9
    tight = _east(12)  # 7.7 m: σ 1.6 m, within END_CHECK_M: the spread alone
    out = end_on_landmark(tight, {"A": (0.0, 0.0, 0.0), "B1": (7.7, 1.0, 0.0),
                                  "B2": (7.7, -1.0, 0.0)})  # fmt: skip
    assert out.end.node in ("B1", "B2") and out.end.sigma <= 3.0
    sig = placement_sigma(out, out.steps.t, out.steps.segment, np.zeros(out.steps.t.size, bool))
    assert out.end.spread == pytest.approx(2.0)
    # a tight end anchors: σ at the end falls below the open stretch's
    assert sig[-1] < placement_sigma(tight, tight.steps.t, tight.steps.segment, np.zeros(tight.steps.t.size, bool))[-1]


@pytest.mark.parametrize("off", [(7.0, 6.0), (30.0, 0.0)])
def test_an_end_far_from_every_landmark_stays_open(off):
    tr = _east(10)  # σ 1.49 m: 6 m is 4σ
    out = end_on_landmark(tr, {"A": (0.0, 0.0, 0.0), "B": (*off, 0.0)})
    assert out.end.node == "" and out.end.how == "far"


def test_a_landmark_on_another_floor_is_no_end_and_a_closed_segment_is_left_alone():
    tr = _east(10)
    assert end_on_landmark(tr, {"A": (0, 0, 0.0), "B": (7.0, 0.0, 1.0)}).end.node == ""
    closed = _east(10, seg_to="B")
    out = end_on_landmark(closed, {"A": (0, 0, 0.0), "B": (7.0, 0.0, 0.0)})
    assert out.end.how == "at_last_match" and out.end.node == "" and out.steps.x_bc is closed.steps.x_bc


def _run(s, g, start, **params):
    return Pipeline(s, g, Params().updated(**{"pdr.start_node": start, **params})).run()


def _off_at_last_tap(s, result) -> float:
    gt = s.ground_truth
    x, y, _ = result.track.position_at(np.array([gt.t[-1]]), corrected=True)
    return math.hypot(x[0] - gt.x[-1], y[0] - gt.y[-1])


def _walks(folder):
    g = LandmarkGraph.load(DATA / "site1_f1_graph.yaml")
    walks = []
    for f in sorted(folder.glob("*.txt.gz")):
        s = load_session(f).in_frame(g.frame)
        walks.append((s, resolve_start("first-fix", s, g)))
    return g, walks


@pytest.fixture(scope="module")
def mall():
    return _walks(DATA)


@pytest.fixture(scope="module")
def short_walks():
    return _walks(SHORT)


def test_real_walks_end_nearer_their_last_tap(mall):
    """The Microsoft walks end at their last tap: where an end is closed, the trajectory the map
    is placed on is nearer it there than the dead reckoning was; elsewhere nothing moves."""
    g, walks = mall
    fwd, cor = [], []
    for s, start in walks:
        on, off = _run(s, g, start), _run(s, g, start, **{"pdr.end_on_landmark": False})
        if not on.track.end.node:
            assert np.array_equal(on.track.steps.x_bc, off.track.steps.x_bc)
            continue
        fwd.append(_off_at_last_tap(s, off))
        cor.append(_off_at_last_tap(s, on))
    assert len(cor) >= 3
    assert np.mean(cor) < np.mean(fwd)


def test_with_no_detection_at_all_an_end_that_checks_the_walk_is_right(short_walks, monkeypatch):
    """The end is what lets a walk that matched no detection into the map (verdict.py), so it is
    checked where nothing else corrects the dead reckoning: the floor's walks of at most 15 s,
    every detection removed. A walk whose end closes within END_CHECK_M is in the map and ends
    within 2.5 m of its last tap (all 106 walks of the floor: 11 such, 0.6 m mean, 1.8 m at
    most). From its given start, every other walk is dead reckoning: not quarantined for it
    (issue #49), its points held to the σ of the open stretch, which grows with the distance
    walked."""
    none = Detections(*(np.empty(0),) * 5)
    monkeypatch.setattr(pipeline, "detect_landmarks", lambda *a, **k: none)
    g, walks = short_walks
    checked = 0
    for s, start in walks:
        r = _run(s, g, start)
        summary = r.summary(s, g).to_json()
        reasons = [q["reason"] for q in summary["quarantine"]]
        if r.track.end.node and summary["end_sigma_m"] <= END_CHECK_M:
            checked += 1
            assert "nothing_matched" not in reasons
            assert _off_at_last_tap(s, r) < 2.5
        else:
            assert "nothing_matched" not in reasons
            sig = r.radiomap.sigma[r.radiomap.segment >= 0]
            assert np.all(np.diff(sig[np.isfinite(sig)]) >= -1e-9) or r.track.end.node
    assert checked >= 5


@pytest.mark.parametrize("kind", ["normal", "varied"])
def test_simulated_walks_end_on_the_landmark_they_end_at(kind):
    """The simulated survey walk ends on its route's last landmark. Over five seeds: an end
    that closes is on the landmark within 1 m of the walker's true end, and the trajectory
    the map is placed on ends nearer the truth than the dead reckoning did; on the normal walk
    every end closes (on the varied one the dead reckoning may end too far off to say)."""
    from workstation.sim import simulate
    from workstation.sim.building import office2f

    b = office2f()
    closed = 0
    for seed in range(1, 6):
        sim = simulate(b, kind, seed, "realistic")
        p = Params().updated(**{"pdr.start_node": b.routes["survey"][0]})
        tr = Pipeline(sim.session, sim.graph, p).run().track
        assert tr.end.how in ("closed", "far", "ambiguous", "at_last_match")
        if not tr.end.node:
            continue
        closed += 1
        end = np.array([tr.steps.t[-1]])
        gx, gy, _ = sim.session.ground_truth.at(end)
        n = sim.graph.node(tr.end.node)
        assert math.hypot(n.x - gx[0], n.y - gy[0]) < 1.0
        (xf, yf, _), (xb, yb, _) = tr.position_at(end), tr.position_at(end, corrected=True)
        assert math.hypot(xb[0] - gx[0], yb[0] - gy[0]) <= math.hypot(xf[0] - gx[0], yf[0] - gy[0])
    assert closed == 5 if kind == "normal" else closed >= 2
