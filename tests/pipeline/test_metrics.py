"""The detectors' and the association figures' definitions on tiny hand-made cases."""

from types import SimpleNamespace

import numpy as np

from tests.pipeline.test_association import rectangle
from workstation.params import GyroLandmarkParams
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import detect_gyro
from workstation.pipeline.metrics import _posi_association
from workstation.pipeline.tracking.state import Start


def test_one_turn_with_two_rate_peaks_is_one_detection():
    """A 150° turn whose rate dips between two peaks (but not below ε_gyro/3) is one turn, at
    its strongest sample, with the whole angle — not one detection per peak."""
    t = np.arange(0, 20, 0.01)
    # turning slowly (0.7 rad/s) from 8.5 to 12 s, with two quick bursts 2.5 s apart
    rate = 0.7 / (1 + np.exp(-(t - 8.5) / 0.1)) / (1 + np.exp((t - 12.0) / 0.1))
    for c, a in ((9.0, 1.0), (11.5, 1.4)):
        rate += a * np.exp(-0.5 * ((t - c) / 0.25) ** 2)
    h = Heading(t, rate, np.cumsum(rate) * 0.01, np.zeros_like(t))
    p = GyroLandmarkParams()
    assert p.merge_s < 1.5  # the bursts are not merged by merge_s: the turn's extent joins them
    out = detect_gyro(h, p)
    assert len(out) == 1
    tk, _, t_end, angle, t_start = out[0]
    assert abs(tk - 11.5) < 0.05
    assert abs(np.degrees(angle) - np.degrees(np.trapezoid(rate, t))) < 10
    assert t_start < 9.0 and t_end > 11.5


def _run(fix_t, fix_xy, matched, steps_t, start=("A", 0.0)):
    g = rectangle()
    mt = np.array([m[0] for m in matched], float)
    node = np.array([m[1] for m in matched], dtype="<U4")
    track = SimpleNamespace(
        start=Start(node=start[0], time=start[1]),
        detections=SimpleNamespace(node=node, matched=np.ones(len(matched), bool)),
    )
    result = SimpleNamespace(
        track=track, landmarks=SimpleNamespace(t=mt), steps=SimpleNamespace(t=np.asarray(steps_t))
    )
    xy = np.asarray(fix_xy, float)
    gt = SimpleNamespace(x=xy[:, 0], y=xy[:, 1], floor=np.zeros(len(xy)), t=np.asarray(fix_t))
    fixes = np.ones(len(xy), bool)
    return _posi_association(result, gt, fixes, g, xy[:, 0], xy[:, 1], np.zeros(len(xy)))


def test_a_visit_is_matched_once_for_all_its_fixes():
    """Arrive at B (fix), turn there (matched), wait 30 s, leave (fix): both fixes count as
    matched (the walker stood on B); the strict figure counts only the fix within ±3 s."""
    steps = np.r_[np.arange(1, 14, 0.5), np.arange(45, 60, 0.5)]  # walk, stand, walk
    m = _run(
        fix_t=[0, 14, 44, 60],
        fix_xy=[(0, 0), (20, 0), (20, 0), (20, 10)],
        matched=[(15.0, "B"), (60.5, "C")],
        steps_t=np.r_[steps, np.arange(60.5, 70, 0.5)],
    )
    assert m["landmark_rule_fixes"] == 4 and m["landmark_fix_match_rate"] == 1.0
    assert m["landmark_fix_match_rate_strict"] == 0.75  # the fix at 44 s is 29 s after the match


def test_a_walk_that_ends_on_a_landmark_leaves_it_out():
    """The walker stops on C and the recording ends: no rule's event can happen there, so the
    last fix is left out of the rate (but not out of the strict one) — unless walking goes on."""
    kw = dict(fix_t=[0, 14], fix_xy=[(0, 0), (20, 0)], matched=[])
    ended = _run(steps_t=np.arange(1, 14.5, 0.5), **kw)
    assert ended["landmark_rule_fixes"] == 1 and ended["landmark_fix_match_rate"] == 1.0
    assert ended["landmark_rule_fixes_strict"] == 2
    assert ended["landmark_fix_match_rate_strict"] == 0.5
    goes_on = _run(steps_t=np.arange(1, 25, 0.5), **kw)
    assert goes_on["landmark_rule_fixes"] == 2 and goes_on["landmark_fix_match_rate"] == 0.5


def test_a_turn_landmark_passed_straight_is_counted_apart():
    """From A east through B without turning (the taps run on to x = 30), then back: B's only
    rule is a turn, so nothing could be detected on the first pass — it is counted in
    passed_straight and left out of the _turned rate; the U-turn at the far end is no landmark.
    The strict rate still counts it as missed."""
    m = _run(
        fix_t=[0, 14, 21, 28, 42],
        fix_xy=[(0, 0), (20, 0), (30, 0), (20, 0.5), (20, 10)],
        matched=[(28.5, "B")],
        steps_t=np.arange(1, 42.5, 0.5),
    )
    # counted: A (the start: matched), B straight on (missed), B turning north (matched); the
    # walk ends on C (left out)
    assert m["landmark_rule_fixes"] == 3 and m["landmark_fix_match_rate"] == round(2 / 3, 4)
    assert m["landmark_rule_fixes_passed_straight"] == 1
    assert m["landmark_fix_match_rate_turned"] == 1.0
