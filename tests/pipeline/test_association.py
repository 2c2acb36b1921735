"""Tracking on tiny synthetic graphs: the confidence of eq. 11-14, floors as they are built, and
the whole-walk (hmm) association against the paper's greedy one, checked against the truth the
walks are generated from (over several seeds)."""

import numpy as np
import pytest

from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline.confidence import (
    confidence,
    distance_sd,
    distance_window,
    gaussian_ll,
)
from workstation.pipeline.floors import FloorModel
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import Detections
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.run import track
from workstation.session import Scalar

SPEED, STEP = 1.4, 0.7  # m/s, m


def rectangle() -> LandmarkGraph:
    """A 20 × 10 m corridor loop, a turn landmark at each corner (asymmetric: 20 ≠ 10)."""
    return LandmarkGraph.from_dict(
        {
            "nodes": [
                {"id": "A", "x": 0, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "B", "x": 20, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "C", "x": 20, "y": 10, "floor": 0, "rules": ["gyro"]},
                {"id": "D", "x": 0, "y": 10, "floor": 0, "rules": ["gyro"]},
            ],
            "edges": [{"from": a, "to": b} for a, b in ("AB", "BC", "CD", "DA")],
        }
    )


def walk(legs, rng, sway=0.03, length_sd=0.0, false_at=()):
    """Steps, heading and turn detections of a walk along ``legs`` [(heading, metres)]."""
    ends = np.cumsum([m for _, m in legs]) / SPEED
    th = np.array([h for h, _ in legs])
    t = np.arange(0, ends[-1] + 1e-9, 0.02)
    leg = np.minimum(np.searchsorted(ends, t), len(legs) - 1)
    heading = np.unwrap(th)[leg] + rng.normal(0, sway, t.size)
    st = np.arange(STEP / SPEED, ends[-1], STEP / SPEED) * (1 + rng.normal(0, length_sd))
    steps = Steps(
        st,
        np.r_[np.nan, np.diff(st)],
        np.ones(st.size),
        t,
        np.ones(t.size),
        np.ones(t.size, bool),
        9.81,
    )
    rate = np.gradient(heading, t)
    hd = Heading(t, rate, heading, (heading + np.pi) % (2 * np.pi) - np.pi)
    turns = ends[:-1]
    dt = np.sort(np.r_[turns, list(false_at)])
    det = Detections(dt, np.full(dt.size, "gyro"), dt + 0.5, np.full(dt.size, np.pi / 2), dt - 0.5)
    return steps, hd, det


LOOP = [(0.0, 20.0), (np.pi / 2, 10.0), (np.pi, 20.0), (-np.pi / 2, 10.0), (0.0, 20.0)]


def test_confidence_is_eq_14():
    assert confidence(20.0, 18.0, True, 0.25) == pytest.approx(0.5)
    assert confidence(20.0, 20.0, True, 0.25) == pytest.approx(4.0)  # floored at 0.25 m
    assert confidence(20.0, 18.0, False, 0.25) == 0.0  # heading off: r = 0 (eq. 13)
    assert distance_sd(0.0, 0.25, 0.1) == pytest.approx(2.0)  # half the paper's 1/ε_v


@pytest.mark.parametrize("cv", [0.0, 0.1, 0.2, 0.4])
def test_distance_window_holds_every_length_within_3_sigma(cv):
    """The association skips level routes outside distance_window unscored: every length whose
    distance term is within 3σ must lie inside it, and lengths well outside must fail."""
    rng = np.random.default_rng(0)
    for d in np.concatenate([[0.0, 1e-3], rng.uniform(0, 300, 200)]):
        lo, hi = distance_window(d, 0.25, cv)
        lengths = rng.uniform(0, 2 * d + 50, 2000)
        fits = gaussian_ll(d - lengths, distance_sd(lengths, 0.25, cv)) >= -4.5
        assert ((lengths >= lo) & (lengths <= hi))[fits].all()
        outside = (lengths < lo - 1e-3) | (lengths > hi + 1e-3)
        assert not fits[outside].any()


@pytest.mark.parametrize("association", ["hmm", "greedy"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_clean_loop_matches_every_corner(association, seed):
    steps, hd, det = walk(LOOP, np.random.default_rng(seed))
    p = Params().pdr.__class__(association=association, start_node="A")
    tr = track(steps, hd, det, rectangle(), None, p, start_time=0.0)
    assert list(tr.detections.node) == ["B", "C", "D", "A"]


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_hmm_leaves_false_turns_unmatched(seed):
    """Turn detections in mid-corridor (a glance at the phone) fit no landmark: the hmm leaves
    them out and still matches every corner; the track ends near the truth."""
    rng = np.random.default_rng(seed)
    steps, hd, det = walk(LOOP, rng, length_sd=0.05, false_at=(5.0, 19.0, 33.0))
    p = Params().pdr.__class__(start_node="A")
    tr = track(steps, hd, det, rectangle(), None, p, start_time=0.0)
    assert [n for n in tr.detections.node if n] == ["B", "C", "D", "A"]
    x, y, _ = tr.position_at([40.0 / SPEED])  # halfway from C to D: (10, 10)
    assert np.hypot(x[0] - 10.0, y[0] - 10.0) < 3.0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_start_inferred_in_one_pass(seed):
    """No start given: every corner starts a hypothesis; only A fits 20, 10, 20, 10 m legs
    heading east first (the compass tells the mirror-image start C apart)."""
    steps, hd, det = walk(LOOP, np.random.default_rng(seed))
    tr = track(steps, hd, det, rectangle(), None, Params().pdr, start_time=0.0)
    assert tr.start.node == "A"
    assert [n for n in tr.detections.node if n] == ["B", "C", "D", "A"]


def test_floor_model_uneven_spacing_and_a_jump_over_a_floor():
    fm = FloorModel.prior([-2, -1, 0], 0.45, p_ref=1000.0, f_ref=0)
    # floors 0.37 and 0.28 hPa apart in truth; from 0 straight down to -2: +0.65 hPa
    assert fm.change_loglik(+0.65, 0, -2) > fm.change_loglik(+0.65, 0, -1) - 1.0
    assert fm.change_loglik(-0.65, 0, -2) == -np.inf  # pressure fell: that was up, not down
    learned = fm.learned(1000.0, 0, 1000.65, -2)
    assert learned.f_ref == -2 and learned.known.all()
    assert learned.gaps.sum() == pytest.approx(0.65)
    assert float(learned.nearest(1000.65)) == -2.0 and float(learned.nearest(1000.0)) == 0.0
    # the eq. 9 prior alone reads 0.65 hPa as 1.44 floors: the wrong floor
    assert float(fm.nearest(1000.65)) == -1.0


def test_floor_heights_stated_by_the_graph():
    g = LandmarkGraph.from_yaml(
        "floors: {0: 0.0, -1: -3.1, -2: -5.4}\n"
        "nodes:\n  - {id: A, x: 0, y: 0, floor: 0}\n  - {id: B, x: 5, y: 0, floor: -2}\n"
        "edges: []\n"
    )
    lv = g.floor_levels_hpa()
    fm = FloorModel.prior(g.floors, 0.45, 1000.0, 0, lv)
    assert fm.known.all() and fm.gaps == pytest.approx([2.3 * 0.12, 3.1 * 0.12])
    assert "floors" in LandmarkGraph.from_yaml(g.to_yaml()).to_dict()
    from workstation.errors import GraphError

    with pytest.raises(GraphError, match="not above"):
        LandmarkGraph.from_yaml("floors: {0: 0.0, 1: -3.0}\nnodes: []\nedges: []\n")


def test_floor_changes_tracked_with_learnt_spacing():
    """A stair landmark pair 0 → -2 in one flight, floors unevenly spaced, no heights given."""
    g = LandmarkGraph.from_dict(
        {
            "nodes": [
                {"id": "S0", "x": 0, "y": 0, "floor": 0, "rules": ["baro_entry", "baro_exit"]},
                {"id": "M", "x": 0, "y": 0, "floor": -1, "rules": ["baro_entry", "baro_exit"]},
                {"id": "S2", "x": 3, "y": 0, "floor": -2, "rules": ["baro_entry", "baro_exit"]},
                {"id": "E", "x": 23, "y": 0, "floor": -2, "rules": ["gyro"]},
            ],
            "edges": [
                {"from": "S0", "to": "S2"},
                {"from": "S2", "to": "E"},
                {"from": "M", "to": "S2"},
            ],
        }
    )
    rng = np.random.default_rng(5)
    steps, hd, _ = walk([(0.0, 3.0), (0.0, 20.0)], rng)
    t_stairs = (0.5, 2.0)  # descending 0.65 hPa (0.37 + 0.28)
    tp = np.arange(0, steps.t[-1] + 2, 0.1)
    pr = 1000 + np.interp(tp, t_stairs, (0.0, 0.65)) + rng.normal(0, 0.005, tp.size)
    det = Detections(
        np.array([t_stairs[1], 23 / SPEED]), np.array(["baro_exit", "gyro"]), np.array([t_stairs[1], 23 / SPEED + 0.5]),
        np.array([0.65, np.pi / 2]), np.array([t_stairs[0], 23 / SPEED - 0.5]),
    )  # fmt: skip
    tr = track(
        steps, hd, det, g, Scalar(tp, pr), Params().pdr.__class__(start_node="S0"), start_time=0.0
    )
    assert list(tr.detections.node) == ["S2", "E"]
    after = tr.steps.t > t_stairs[1] + 0.5
    assert np.all(tr.steps.floor[after] == -2)


def _stacked(floors=(0, -1)) -> LandmarkGraph:
    """The rectangle on several floors, one above the other, not connected."""
    d = rectangle().to_dict()
    nodes = [dict(n, id=f"{n['id']}{f}", floor=f) for f in floors for n in d["nodes"]]
    edges = [{"from": f"{e['from']}{f}", "to": f"{e['to']}{f}"} for f in floors for e in d["edges"]]
    return LandmarkGraph.from_dict({"nodes": nodes, "edges": edges})


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_an_inferred_start_says_when_it_is_ambiguous(seed):
    """The same loop on two stacked floors and no barometer: starting on either floor explains
    the walk equally well, and the summary says so; on one floor the start is clear."""
    from workstation.pipeline.metrics import START_AMBIGUOUS_MARGIN

    steps, hd, det = walk(LOOP, np.random.default_rng(seed))
    tr = track(steps, hd, det, _stacked(), None, Params().pdr, start_time=0.0)
    assert tr.start.node in ("A0", "A-1")
    assert tr.start.alternative == ({"A0", "A-1"} - {tr.start.node}).pop()
    assert tr.start.margin < START_AMBIGUOUS_MARGIN
    one = track(steps, hd, det, _stacked((0,)), None, Params().pdr, start_time=0.0)
    assert one.start.node == "A0" and one.start.margin >= START_AMBIGUOUS_MARGIN
    given = track(steps, hd, det, _stacked(), None, Params().pdr, "A0", start_time=0.0)
    assert given.start.alternative == "" and np.isnan(given.start.margin)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_clear_match_has_no_spread(seed):
    """Corners 10 and 20 m apart: no nearly as likely association puts any turn elsewhere."""
    steps, hd, det = walk(LOOP, np.random.default_rng(seed))
    p = Params().pdr.__class__(start_node="A")
    tr = track(steps, hd, det, rectangle(), None, p, start_time=0.0)
    assert tr.detections.spread is not None and np.all(tr.detections.spread == 0.0)


def _two_corners(gap: float) -> LandmarkGraph:
    """An open hall east of A with two corridors north from it, ``gap`` metres apart (B1, B2),
    each reached straight from A."""
    return LandmarkGraph.from_dict(
        {
            "nodes": [
                {"id": "A", "x": 0, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "B1", "x": 20, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "B2", "x": 20 + gap, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "C1", "x": 20, "y": 10, "floor": 0},
                {"id": "C2", "x": 20 + gap, "y": 10, "floor": 0},
            ],
            "edges": [{"from": a, "to": b} for a, b in
                      (("A", "B1"), ("A", "B2"), ("B1", "C1"), ("B2", "C2"))],
        }
    )  # fmt: skip


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_turn_between_two_corners_is_as_uncertain_as_they_are_apart(seed):
    """The walker turns north halfway between two side corridors 3 m apart: either explains
    the walk nearly as well, so the match is uncertain by their distance, and so is every scan
    placed from it (σ, pipeline/sigma.py); 30 m apart the turn is clearly the nearer one."""
    from workstation.pipeline.sigma import SCALE, placement_sigma

    rng = np.random.default_rng(seed)
    steps, hd, det = walk([(0.0, 21.5), (np.pi / 2, 10.0)], rng)
    p = Params().pdr.__class__(start_node="A")
    tr = track(steps, hd, det, _two_corners(3.0), None, p, start_time=0.0)
    k = int(np.flatnonzero(tr.detections.matched)[0])
    assert tr.detections.spread[k] == pytest.approx(3.0)
    t = np.array([det.t[k] + 1.0])  # a scan a step or so after the turn: σ at least the spread
    # (σ is the 68 % radius: the spreads' sum times sigma.SCALE)
    assert placement_sigma(tr, t, np.array([1]), np.zeros(1, bool))[0] >= SCALE * 3.0
    steps, hd, det = walk([(0.0, 20.0), (np.pi / 2, 10.0)], rng)
    tr = track(steps, hd, det, _two_corners(30.0), None, p, start_time=0.0)
    assert list(tr.detections.node) == ["B1"] and tr.detections.spread[0] == 0.0


def _scorer(legs, det=None, seed=1):
    from types import SimpleNamespace

    from workstation.pipeline.reach import Reach
    from workstation.pipeline.tracking.tracker import Tracker

    steps, hd, turns = walk(legs, np.random.default_rng(seed))
    p = Params().pdr
    trk = Tracker(steps, hd, det or turns, Reach(rectangle(), p.max_hops), None, p, 0.0)
    return trk, SimpleNamespace(offset=0.0)


def test_a_turn_leaving_along_an_edge_scores_above_one_leaving_where_none_goes():
    """candidates._exit_ll: after the turn at B the walk goes north, along B–C: log-ratio > 0;
    a walk turning south at B leaves where no edge goes: < 0; at A (edges east and north) the
    northward way out fits too. The ratio is 0 for a turn inside a detected floor change."""
    trk, st = _scorer(LOOP)
    north = trk.scoring._exit_ll(st, 0, "B")  # detection 0: the turn at B, then 10 m north
    assert north > 0.5  # at most ln(2π·(0.9·N(0; 30°)/2 + 0.1/2π)) = 0.81 with two ways out
    assert trk.scoring._exit_ll(st, 0, "A") > 0.5  # A–D leaves north as well
    south, _ = _scorer([(0.0, 20.0), (-np.pi / 2, 10.0), (np.pi, 20.0)])
    assert south.scoring._exit_ll(st, 0, "B") < -1.0
    # the same turn inside a floor change (a baro_exit whose pattern began before it)
    steps, hd, det = walk(LOOP, np.random.default_rng(1))
    t = det.t[0]
    climb = Detections(
        np.r_[det.t, t + 2.0], np.concatenate([det.kind, ["baro_exit"]]),
        np.r_[det.t_end, t + 2.0], np.r_[det.value, -0.4], np.r_[det.t_start, t - 5.0],
    )  # fmt: skip
    order = np.argsort(climb.t, kind="stable")
    climb = Detections(*(a[order] for a in (climb.t, climb.kind, climb.t_end, climb.value,
                                            climb.t_start)))  # fmt: skip
    trk2, _ = _scorer(LOOP, det=climb)
    assert trk2.scoring._exit_ll(st, 0, "B") == 0.0
