"""The walk ends on a landmark (pipeline/walk_end.py): on hand-made tracks where the answer is
known, and on ten real mall walks (tests/data/msilc, MIT) whose last tap is where they end."""

import math

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.sigma import BASE_M, open_sigma, placement_sigma
from workstation.pipeline.start import resolve_start
from workstation.pipeline.tracking import Track
from workstation.pipeline.walk_end import end_on_landmark
from workstation.session import load_session

DATA = REPO / "tests" / "data" / "msilc"


def _east(n_steps: int, length: float = 0.7, seg_to: str = "") -> Track:
    """One segment from A at the origin, ``n_steps`` steps due east."""
    t = np.arange(1, n_steps + 1, dtype=float)
    x = t * length
    z = np.zeros(n_steps)
    return Track(
        t=t, x=x, y=z, floor=z, heading=z, step_length=z + length, segment=np.zeros(n_steps, int),
        x_bc=x.copy(), y_bc=z.copy(), raw_x=x.copy(), raw_y=z.copy(),
        det_node=np.array([], str), det_confidence=z[:0], det_candidate=np.array([], str),
        det_reason=np.array([], str), det_spread=z[:0], seg_from=np.array(["A"]),
        seg_to=np.array([seg_to]), seg_t0=np.array([0.0]), seg_t1=np.array([t[-1]]),
        seg_missed=np.zeros(1, np.int64), start_node="A", start_time=0.0, floor_gaps_hpa={},
    )  # fmt: skip


def test_an_open_end_near_one_landmark_is_closed_on_it():
    tr = _east(10)  # ends at (7, 0); σ = hypot(0.5, 0.2 · 7) = 1.49 m
    pos = {"A": (0.0, 0.0, 0.0), "B": (7.5, 0.4, 0.0), "C": (20.0, 0.0, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end_node == "B"
    assert out.seg_to.tolist() == ["B"]
    assert (out.x_bc[-1], out.y_bc[-1]) == pytest.approx((7.5, 0.4))
    assert np.array_equal(out.x, tr.x) and np.array_equal(out.y, tr.y)  # forward untouched
    # the likeliest place elsewhere (> 5 m from B) is A, 7 m behind, against B 0.64 m off
    sd = open_sigma(0.0, 7.0)
    assert out.end_margin == pytest.approx(0.5 * (7.0**2 - 0.5**2 - 0.4**2) / sd**2, rel=0.02)
    # the segment is closed now: σ falls towards its end instead of growing
    sig = placement_sigma(out, out.t, out.segment, np.zeros(out.t.size, bool))
    assert sig[-1] == pytest.approx(BASE_M, abs=0.05)
    assert sig[-1] < placement_sigma(tr, tr.t, tr.segment, np.zeros(tr.t.size, bool))[-1]


def test_two_places_nearly_as_likely_leave_the_end_open():
    tr = _east(40)  # 28 m: σ = hypot(0.5, 5.6) = 5.6 m; B1 and B2 are 6 m apart, both 3 m off
    pos = {"A": (0.0, 0.0, 0.0), "B1": (28.0, 3.0, 0.0), "B2": (28.0, -3.0, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end_node == "" and out.seg_to.tolist() == [""]
    assert out.end_margin == pytest.approx(0.0, abs=1e-6)
    assert np.array_equal(out.x_bc, tr.x_bc)


def test_landmarks_a_metre_or_two_apart_are_one_place_and_its_spread_is_kept():
    tr = _east(40)
    pos = {"A": (0.0, 0.0, 0.0), "B1": (28.0, 1.0, 0.0), "B2": (28.0, -1.5, 0.0)}
    out = end_on_landmark(tr, pos)
    assert out.end_node == "B1"
    assert out.end_spread == pytest.approx(2.5)
    sig = placement_sigma(out, out.t, out.segment, np.zeros(out.t.size, bool))
    assert sig[-1] == pytest.approx(math.hypot(BASE_M, 2.5), abs=0.1)


@pytest.mark.parametrize("off", [(7.0, 6.0), (30.0, 0.0)])
def test_an_end_far_from_every_landmark_stays_open(off):
    tr = _east(10)  # σ 1.49 m: 6 m is 4σ
    out = end_on_landmark(tr, {"A": (0.0, 0.0, 0.0), "B": (*off, 0.0)})
    assert out.end_node == ""


def test_a_landmark_on_another_floor_is_no_end_and_a_closed_segment_is_left_alone():
    tr = _east(10)
    assert end_on_landmark(tr, {"A": (0, 0, 0.0), "B": (7.0, 0.0, 1.0)}).end_node == ""
    closed = _east(10, seg_to="B")
    assert end_on_landmark(closed, {"A": (0, 0, 0.0), "B": (7.0, 0.0, 0.0)}) is closed


@pytest.fixture(scope="module")
def mall():
    g = LandmarkGraph.load(DATA / "site1_f1_graph.yaml")
    out = []
    for f in sorted(DATA.glob("*.txt.gz")):
        s = load_session(f).in_frame(g.frame)
        start = resolve_start("first-fix", s, g)
        runs = [
            Pipeline(s, g, Params().updated(**{"pdr.start_node": start,
                                               "pdr.end_on_landmark": on})).run()  # fmt: skip
            for on in (True, False)
        ]
        out.append((s, runs))
    return g, out


def test_real_walks_end_nearer_their_last_tap_and_quarantines_stay(mall):
    """The Microsoft walks end at their last tap: where an end is closed, the trajectory the map
    is placed on is nearer it there than the dead reckoning was. Ending on a landmark is no
    match: a walk that matched nothing stays quarantined."""
    g, walks = mall
    fwd, cor = [], []
    for s, (on, off) in walks:
        gt = s.ground_truth
        last = np.array([gt.t[-1]])
        assert (on.summary(s, g)["quarantine"] == []) == (off.summary(s, g)["quarantine"] == [])
        if not on.track.end_node:
            assert np.array_equal(on.track.x_bc, off.track.x_bc)
            continue
        for tr_xy, out in ((off.track.position_at(last, corrected=True), fwd),
                           (on.track.position_at(last, corrected=True), cor)):  # fmt: skip
            out.append(math.hypot(tr_xy[0][0] - gt.x[-1], tr_xy[1][0] - gt.y[-1]))
    assert len(cor) >= 3
    assert np.mean(cor) < np.mean(fwd)
