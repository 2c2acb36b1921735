"""Belief segment boundaries at landmark stops, and scans taken at a landmark stop (issue #11),
on hand-made steps and tracks where the right answer is known."""

import numpy as np
import pytest

from workstation.params import BeliefParams, RadioMapParams
from workstation.pipeline.belief import compute_belief, landmark_stops, still_runs
from workstation.pipeline.radiomap import build_radiomap
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.state import Detections, End, Segments, Start, Track
from workstation.pipeline.tracking.state import Steps as TrackSteps
from workstation.session.model import WifiScans

FS = 50.0


def _steps(step_t, still_spans, t_end=60.0, jitter=0.0, seed=0):
    t = np.asarray(step_t, float)
    t = t + np.random.default_rng(seed).normal(0, jitter, t.size) if jitter else t
    st = np.arange(0.0, t_end, 1 / FS)
    walking = np.ones(st.size, bool)
    for a, b in still_spans:
        walking[(st >= a) & (st <= b)] = False
    period = np.concatenate([[np.nan], np.diff(t)])
    return Steps(t, period, np.ones(t.size), st, np.zeros(st.size), walking, 9.81)


def _track(steps, seg_t0, seg_from, seg_to, seg_missed=None):
    n = steps.t.size
    seg = np.searchsorted(seg_t0, steps.t, side="right") - 1
    z = np.zeros(n)
    nseg = len(seg_t0)
    return Track(
        TrackSteps(t=steps.t, x=steps.t.copy(), y=z, floor=z, heading=z,
                   step_length=np.r_[0.7, np.diff(steps.t)],  # x moves by the steps' lengths
                   segment=seg, x_bc=steps.t.copy(), y_bc=z, raw_x=z, raw_y=z),
        Detections(node=np.array([], str), confidence=z[:0], candidate=np.array([], str),
                   reason=np.array([], str), spread=z[:0]),
        Segments(from_node=np.array(seg_from), to_node=np.array(seg_to),
                 t0=np.asarray(seg_t0, float),
                 t1=np.asarray(list(seg_t0[1:]) + [steps.t[-1]], float),
                 missed=np.zeros(nseg, np.int64) if seg_missed is None else np.asarray(seg_missed)),
        Start(node=seg_from[0], time=float(seg_t0[0])),
    )  # fmt: skip


def _walk(jitter=0.01, seed=0, mid_stop=False):
    """Stand 0–10 s at A; walk to B (10–20 s); stop at B 20–25 s (its turn detected at 21 s);
    walk to C (25–35 s, optionally a 3 s stop mid-way); stop at C."""
    leg1 = np.arange(10.5, 20.01, 0.5)
    leg2 = np.arange(25.5, 35.01, 0.5)
    still = [(0, 10.2), (20.2, 25.2), (35.2, 40)]
    if mid_stop:
        leg2 = np.concatenate([np.arange(25.5, 29.01, 0.5), np.arange(32.5, 35.01, 0.5)])
        still.append((29.2, 32.2))
    s = _steps(np.concatenate([leg1, leg2]), still, jitter=jitter, seed=seed)
    return s, _track(s, [10.0, 21.0, 35.5], ["A", "B", "C"], ["B", "C", ""])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_stops_at_landmarks_are_not_step_periods(seed):
    s, tr = _walk(seed=seed)
    p = BeliefParams()
    b = compute_belief(s, tr, p)
    paper = compute_belief(s, tr, BeliefParams(landmark_stops_apart=False))
    # the 5 s stop at B became one 5 s "period" of segment 1 in the paper's counting
    assert paper.valid_ratio[1] < 0.8
    assert b.valid_ratio[1] == pytest.approx(1.0)
    assert b.belief[0] > p.threshold and b.belief[1] > p.threshold
    assert b.accepted[:2].all() and not b.accepted[2]  # the open segment is never trusted
    assert b.reason[2].startswith("open")
    # the first step (its period spans the stand before the walk) is not counted
    assert not b.counted[0] and b.counted[1]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_stop_inside_a_segment_still_counts(seed):
    s, tr = _walk(seed=seed, mid_stop=True)
    b = compute_belief(s, tr, BeliefParams())
    assert b.valid_ratio[1] < 0.8
    assert b.belief[1] < b.belief[0]


def test_a_segment_that_skips_a_detectable_landmark_is_not_trusted():
    s, tr = _walk()
    from dataclasses import replace

    b = compute_belief(
        s, replace(tr, segments=replace(tr.segments, missed=np.array([0, 1, 0]))), BeliefParams()
    )
    assert b.accepted[0] and not b.accepted[1]
    assert "not detected" in b.reason[1]
    b = compute_belief(
        s, replace(tr, segments=replace(tr.segments, missed=np.array([-1, 0, 0]))), BeliefParams()
    )
    assert not b.accepted[0] and "lost" in b.reason[0]


def test_still_runs_and_landmark_stops():
    s, _ = _walk()
    a, b = still_runs(s)
    assert a[1] == pytest.approx(20.2, abs=0.03) and b[1] == pytest.approx(25.2, abs=0.03)
    lo, hi = landmark_stops(s, np.array([21.0, 31.0, 45.0]), 3.0)
    assert lo[0] == pytest.approx(20.2, abs=0.03) and hi[0] == pytest.approx(25.2, abs=0.03)
    assert np.isnan(lo[1]) and np.isnan(lo[2])  # nothing still within 3 s


def test_scans_at_a_landmark_stop_are_reference_points_on_it():
    s, tr = _walk()
    b = compute_belief(s, tr, BeliefParams(threshold=1e3))  # nothing trusted by belief
    times = np.array([15.0, 22.0, 24.5, 30.0])
    ap = np.array(["ap"] * 4)
    wifi = WifiScans(times, ap, ap, np.full(4, 2412.0), np.array([-60.0, -61, -62, -70]))
    lm = {"A": (0.0, 0.0, 0.0), "B": (50.0, 5.0, 0.0), "C": (90.0, 0.0, 0.0)}
    rm = build_radiomap(wifi, tr, b, RadioMapParams(acceptance="belief"), lm)
    assert rm.at_landmark.tolist() == [False, True, True, False]
    assert rm.accepted.tolist() == [False, True, True, False]
    assert rm.x[1] == 50.0 and rm.y[2] == 5.0
    off = build_radiomap(
        wifi, tr, b, RadioMapParams(acceptance="belief", scans_at_landmark_stops=False), lm
    )
    assert not off.accepted.any()
    # the stop at B was a lift: from 23.5 s the pressure falls a storey (0.4 hPa in 1 s) — the
    # scan at 24.5 s is no longer at B
    from workstation.session import Scalar

    tp = np.arange(0.0, 40.0, 0.1)
    pressure = Scalar(tp, 1000.0 + np.clip(tp - 23.5, 0.0, 1.0) * 0.4)
    lift = build_radiomap(wifi, tr, b, RadioMapParams(acceptance="belief"), lm, pressure)
    assert lift.at_landmark.tolist() == [False, True, False, False]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_reference_points_are_on_the_floor_walked(seed):
    """Simulated office with lift rides and stairs, a scan every 0.5–1 s: the accepted
    reference points carry the true floor (the simulator's), but for the odd one on a stair
    flight; none placed at a landmark is on another floor (a stop in a lift rides on)."""
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.sim import simulate

    sim = simulate("office2f", "normal", seed, "realistic", (0.5, 1.0))
    p = Params().updated(**{"pdr.start_node": sim.building.routes["survey"][0]})
    rm = Pipeline(sim.session, sim.graph, p).run().radiomap
    _, _, truth = sim.session.ground_truth.at(rm.t)
    wrong = (np.abs(rm.floor - truth) > 0.5) & rm.accepted
    assert wrong.sum() <= 0.01 * rm.accepted.sum(), int(wrong.sum())
    assert not (wrong & rm.at_landmark).any()


def test_gaps_in_the_trusted_map_are_filled_from_near_threshold_segments():
    """Segment 0 (A→B) trusted, segment 1 (B→C) just under ε_S: its scans far from every
    trusted scan are kept, those near are not; far under ε_S nothing is kept."""
    s, tr = _walk()
    b = compute_belief(s, tr, BeliefParams())
    times = np.array([12.0, 18.0, 27.0, 34.0])  # x = t on this track
    ap = np.array(["ap"] * 4)
    wifi = WifiScans(times, ap, ap, np.full(4, 2412.0), np.array([-60.0, -61, -62, -70]))
    from dataclasses import replace

    near = replace(b, accepted=np.array([True, False, False]), belief=np.array([40.0, 10.0, 0]))
    rm = build_radiomap(
        wifi, tr, near, RadioMapParams(acceptance="belief", backward_correction=False), None
    )
    assert rm.accepted.tolist() == [True, True, True, True]  # 27, 34 are > 3 m from 18
    assert rm.filled.tolist() == [False, False, True, True]
    rm = build_radiomap(
        wifi,
        tr,
        near,
        RadioMapParams(acceptance="belief", backward_correction=False, fill_gaps_m=12.0),
        None,
    )
    assert rm.filled.tolist() == [False, False, False, True]  # 27 is within 12 m of 18
    far = replace(near, belief=np.array([40.0, 5.0, 0]))
    rm = build_radiomap(
        wifi, tr, far, RadioMapParams(acceptance="belief", backward_correction=False), None
    )
    assert rm.accepted.tolist() == [True, True, False, False]
    # a segment re-found after the track was lost has no known path: never a gap fill
    lost = replace(tr, segments=replace(tr.segments, missed=np.array([0, -1, 0])))
    rm = build_radiomap(
        wifi, lost, near, RadioMapParams(acceptance="belief", backward_correction=False), None
    )
    assert rm.accepted.tolist() == [True, True, False, False]


def test_no_gap_fill_on_a_last_segment_closed_by_an_end_too_loose_to_check_the_walk():
    """The walk's end closed its last segment (B→C) on C: placed to within END_CHECK_M, the
    segment's scans fill gaps as a matched segment's do; placed more loosely, they do not (the
    end bent the segment, it did not check it)."""
    from dataclasses import replace

    from workstation.pipeline.tracking.state import END_CHECK_M

    s, _ = _walk()
    tr = _track(s, [10.0, 21.0], ["A", "B"], ["B", "C"])
    times = np.array([12.0, 18.0, 27.0, 34.0])
    ap = np.array(["ap"] * 4)
    wifi = WifiScans(times, ap, ap, np.full(4, 2412.0), np.array([-60.0, -61, -62, -70]))
    b = compute_belief(s, tr, BeliefParams())
    near = replace(b, accepted=np.array([True, False]), belief=np.array([40.0, 10.0]))
    p = RadioMapParams(acceptance="belief", backward_correction=False)
    for sd, fills in ((END_CHECK_M, True), (END_CHECK_M + 0.5, False), (14.0, False)):
        ended = replace(tr, end=End(node="C", how="closed", sigma=sd))
        rm = build_radiomap(wifi, ended, near, p, None)
        assert rm.filled.tolist() == [False, False, fills, fills], sd
    # the surveyor's end is the surveyor's word, however loosely the sensors placed it
    given = replace(tr, end=End(node="C", how="given", sigma=14.0))
    assert build_radiomap(wifi, given, near, p, None).filled[2:].all()


def test_scans_between_steps_on_two_floors_are_no_reference_points():
    """A lift ride: no steps from 20 to 25.5 s, the step before on floor 0, the one after on
    floor 1. The scans taken in between belong to neither floor, even in a trusted segment;
    the scans around the ride, between steps on one floor, stay."""
    s, tr = _walk()
    from dataclasses import replace

    tr = replace(tr, steps=replace(tr.steps, floor=np.where(tr.steps.t > 22.0, 1.0, 0.0)))
    b = compute_belief(s, tr, BeliefParams(threshold=0.0))  # every segment trusted
    times = np.array([15.0, 21.0, 24.9, 30.0])
    ap = np.array(["ap"] * 4)
    wifi = WifiScans(times, ap, ap, np.full(4, 2412.0), np.array([-60.0, -61, -62, -70]))
    rm = build_radiomap(
        wifi, tr, b, RadioMapParams(acceptance="belief", scans_at_landmark_stops=False), None
    )
    assert rm.accepted.tolist() == [True, False, False, True]
    assert rm.floor.tolist() == [0.0, 0.0, 0.0, 1.0]
    # the same scans taken standing at B, a matched landmark on floor 1: placed on it
    lm = {"A": (0.0, 0.0, 0.0), "B": (50.0, 5.0, 1.0), "C": (90.0, 0.0, 1.0)}
    rm = build_radiomap(wifi, tr, b, RadioMapParams(acceptance="belief"), lm)
    assert rm.accepted.tolist() == [True, True, True, True]
    assert rm.floor.tolist() == [0.0, 1.0, 1.0, 1.0]
