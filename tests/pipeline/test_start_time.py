"""When a walk starts (pipeline/start.py): at the first walking, after a stand when there is
one, never at a mid-walk stop — on motion patterns built sample by sample, several seeds."""

import numpy as np
import pytest

from workstation.params import Params
from workstation.pipeline.heading import Heading
from workstation.pipeline.start import start_time
from workstation.pipeline.steps import Steps

FS = 50.0
P = Params().pdr


def _motion(pattern, seed):
    """Steps/heading from ``pattern``: (seconds, "walk" | "still" | "handle") pieces, with
    each boundary jittered by up to 0.3 s."""
    rng = np.random.default_rng(seed)
    walking, rate, bounds, t0 = [], [], [], 0.0
    for dur, kind in pattern:
        dur = max(dur + rng.uniform(-0.3, 0.3), 0.1)
        n = int(dur * FS)
        walking.append(np.full(n, kind != "still"))
        base = {"walk": 0.4, "still": 0.05, "handle": 4.0}[kind]
        rate.append(np.abs(base + rng.normal(0, 0.15 * base + 0.02, n)))
        bounds.append((t0, kind))
        t0 += n / FS
    w, r = np.concatenate(walking), np.concatenate(rate)
    t = np.arange(w.size) / FS
    st = t[w][:: int(FS * 0.55)]  # a step every 0.55 s while moving
    e = np.empty(0)
    steps = Steps(st, np.diff(st, prepend=np.nan), np.ones(st.size), t, w * 2.0, w, 9.81)
    return steps, Heading(t, e, e, e, r), bounds


def _start_of(bounds, index):
    return bounds[index][0]


@pytest.mark.parametrize("seed", range(5))
def test_a_walk_that_sets_off_at_once_starts_with_its_first_sample(seed):
    steps, h, _ = _motion([(25, "walk"), (12, "still"), (30, "walk")], seed)
    st = start_time(steps, P, h)
    assert st.t < 0.1 and st.how == "walking"  # the mid-walk stop does not pull it later


@pytest.mark.parametrize("seed", range(5))
def test_a_stand_before_setting_off_is_used(seed):
    steps, h, b = _motion([(8, "still"), (40, "walk")], seed)
    st = start_time(steps, P, h)
    assert st.how == "after_stand" and abs(st.t - _start_of(b, 1)) < 0.1


@pytest.mark.parametrize("seed", range(5))
def test_handling_then_a_stand_then_walking_starts_after_the_stand(seed):
    # the museum's walkers: calibration figure-eights (the accelerometer takes them for
    # steps), a short shuffle, a long stand at the start landmark, then the walk
    pattern = [(20, "handle"), (1.0, "still"), (12, "handle"), (3, "still"), (1.2, "walk"),
               (25, "still"), (60, "walk")]  # fmt: skip
    steps, h, b = _motion(pattern, seed)
    st = start_time(steps, P, h)
    assert st.how == "after_handling" and abs(st.t - _start_of(b, 6)) < 0.1


@pytest.mark.parametrize("seed", range(5))
def test_a_vigorous_walker_is_not_taken_for_handling_without_a_stand(seed):
    # the phone swung in the hand turns fast, but nobody stands before the walk goes on
    steps, h, _ = _motion([(15, "handle"), (1.0, "still"), (20, "walk"), (8, "still"),
                           (10, "walk")], seed)  # fmt: skip
    st = start_time(steps, P, h)
    assert st.t < 0.1


@pytest.mark.parametrize("seed", range(5))
def test_a_few_steps_then_a_pause_are_the_start(seed):
    # three steps, a 1-s pause (no stand), then on: the walk began with the first steps
    steps, h, _ = _motion([(1.9, "walk"), (1.2, "still"), (30, "walk")], seed)
    assert start_time(steps, P, h).t < 0.1


def test_no_walking_at_all():
    steps, h, _ = _motion([(30, "still")], 0)
    st = start_time(steps, P, h)
    assert st.how == "no_walking" and st.t == 0.0
