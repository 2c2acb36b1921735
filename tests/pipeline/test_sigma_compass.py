"""σ where the compass denies the placed track (pipeline/sigma.py, ``compass_drift``): a stretch
whose direction is Δ beyond the gate ``COMPASS_GATE_DEG`` off the compass went elsewhere by the
chord 2 sin((Δ − gate)/2) per metre, which σ carries — and the landmark reached along it anchors no better;
a compass within the gate, or none, adds nothing. Several seeds of the walker's sway and of the
compass's own noise."""

import numpy as np
import pytest

from tests.pipeline.test_association import walk
from tests.pipeline.test_sigma_snap import _corner
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline.heading import Heading
from workstation.pipeline.sigma import COMPASS_GATE_DEG, compass_drift, placement_sigma
from workstation.pipeline.tracking.run import track

PDR = Params().pdr.__class__(start_node="A")


def _compass(hd: Heading, offset: np.ndarray, rng, noise_deg: float = 10.0) -> Heading:
    """``hd`` with its compass turned by ``offset`` (rad, per sample) and noisy."""
    c = hd.gyro + offset + rng.normal(0.0, np.radians(noise_deg), hd.t.size)
    return Heading(hd.t, hd.vertical_rate, hd.gyro, (c + np.pi) % (2 * np.pi) - np.pi)


def _corridor() -> LandmarkGraph:
    return LandmarkGraph.from_dict({
        "nodes": [{"id": "A", "x": 0, "y": 0, "floor": 0}, {"id": "B", "x": 40, "y": 0, "floor": 0}],
        "edges": [{"from": "A", "to": "B"}],
    })  # fmt: skip


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("turned_deg", [20.0, 60.0, 90.0])
def test_a_straight_walk_the_compass_turns_away_from_carries_the_chord(seed, turned_deg):
    """20 m east, the compass turned by a fixed angle: under the gate nothing; over it, the
    whole walk's sum is the chord 2 sin((Δ − gate)/2) per metre over (nearly) the 20 m."""
    rng = np.random.default_rng(seed)
    steps, hd, det = walk([(0.0, 20.0)], rng)
    tr = track(steps, hd, det, _corridor(), None, PDR, start_time=0.0)
    along, total = compass_drift(tr, _compass(hd, np.radians(turned_deg), rng))
    walked = float(np.hypot(np.diff(tr.steps.x_bc), np.diff(tr.steps.y_bc)).sum())
    if turned_deg < COMPASS_GATE_DEG:
        assert total.sum() == 0.0 and not along.any()
    else:
        chord = 2 * np.sin(np.radians(turned_deg - COMPASS_GATE_DEG) / 2) * walked
        assert 0.85 * chord <= total.sum() <= 1.05 * chord
        assert np.all(np.diff(along) >= 0) and along[-1] == pytest.approx(total.sum())


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_a_turn_the_compass_did_not_see_widens_sigma_after_it(seed):
    """East 10 m, a turn landmark, north 10 m — but the compass kept pointing east after the
    turn (the walker went on east; the match turned the track): the segment after the match
    carries the chord (≈ 10 m over 10 m at 90°, beyond a 30° gate), a scan there has σ at least what it went
    elsewhere by then; with the compass agreeing, σ is as without one."""
    rng = np.random.default_rng(seed)
    steps, hd, det = walk([(0.0, 10.0), (np.pi / 2, 10.0)], rng)
    tr = track(steps, hd, det, _corner(10.5), None, PDR, start_time=0.0)
    assert list(tr.detections.node) == ["B"]
    agree = _compass(hd, np.zeros(hd.t.size), rng)
    after = hd.t >= det.t[0]
    denied = _compass(hd, np.where(after, -np.pi / 2, 0.0), rng)
    _, total_ok = compass_drift(tr, agree)
    along, total = compass_drift(tr, denied)
    assert total_ok.sum() == 0.0
    chord = 2 * np.sin(np.radians(90.0 - COMPASS_GATE_DEG) / 2) * 10.0
    assert total[0] < 1.0 and 0.6 * chord <= total[1] <= 1.1 * chord
    t = np.array([det.t[0] + 6.0])  # a scan 6 s after the turn
    plain = placement_sigma(tr, t, np.array([1]), np.zeros(1, bool))[0]
    with_ok = placement_sigma(tr, t, np.array([1]), np.zeros(1, bool), heading=agree)[0]
    with_denied = placement_sigma(tr, t, np.array([1]), np.zeros(1, bool), heading=denied)[0]
    at_scan = float(np.interp(t[0], tr.steps.t, along))
    assert with_ok == pytest.approx(plain)
    assert at_scan > 2.0 and with_denied >= plain + at_scan - 1e-9


def test_no_compass_adds_nothing():
    rng = np.random.default_rng(0)
    steps, hd, det = walk([(0.0, 20.0)], rng)
    tr = track(steps, hd, det, _corridor(), None, PDR, start_time=0.0)
    none = Heading(hd.t, hd.vertical_rate, hd.gyro, np.full(hd.t.size, np.nan))
    for h in (None, none):
        along, total = compass_drift(tr, h)
        assert not along.any() and not total.any()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_scan_only_the_compass_held_back_says_so_and_waits_on_standby(seed):
    """The turn the compass did not see: scans well after it are over the σ cut only for the
    compass's part, and say so (the surveyor checks the match before them) — on standby like
    any scan held back for its σ; with the compass agreeing they are reference points."""
    from workstation.params import BeliefParams, RadioMapParams
    from workstation.pipeline.belief import compute_belief
    from workstation.pipeline.radiomap import WHY_NOT, build_radiomap
    from workstation.session.model import WifiScans

    rng = np.random.default_rng(seed)
    steps, hd, det = walk([(0.0, 10.0), (np.pi / 2, 12.0)], rng)
    tr = track(steps, hd, det, _corner(10.5), None, PDR, start_time=0.0)
    b = compute_belief(steps, tr, BeliefParams())
    times = det.t[0] + np.array([-4.0, 7.0, 8.0])  # before the turn, and well after it
    ap = np.array(["ap"] * times.size)
    wifi = WifiScans(times, ap, ap, np.full(times.size, 2412.0), np.full(times.size, -60.0))
    after = hd.t >= det.t[0]
    agree = _compass(hd, np.zeros(hd.t.size), rng)
    denied = _compass(hd, np.where(after, -np.pi / 2, 0.0), rng)
    p = RadioMapParams()
    ok = build_radiomap(wifi, tr, b, p, None, heading=agree)
    off = build_radiomap(wifi, tr, b, p, None, heading=denied)
    assert ok.accepted.all() and not ok.held_for_sigma.any()
    assert off.accepted[0] and not off.accepted[1:].any()
    assert list(off.why_not[1:]) == [WHY_NOT["compass"]] * 2
    assert off.held_for_sigma[1:].all() and off.not_points() == {WHY_NOT["compass"]: 2}
