"""Table I's windows are sample counts of a 50-Hz phone (``filters.samples_at``): the same walk
sampled faster gives the same steps and turns (issue #33: a 500-Hz IMU gave 2 steps for 502)."""

from dataclasses import replace

import numpy as np
import pytest

from workstation.params import Params
from workstation.pipeline.filters import samples_at
from workstation.pipeline.heading import estimate_heading
from workstation.pipeline.landmarks import detect_landmarks
from workstation.pipeline.steps import detect_steps
from workstation.session.model import Vector3
from workstation.sim import simulate


def _resampled(v: Vector3, hz: float) -> Vector3:
    t = np.arange(v.t[0], v.t[-1], 1.0 / hz)
    return Vector3(t, np.column_stack([np.interp(t, v.t, v.xyz[:, k]) for k in range(3)]))


def test_samples_at_keeps_the_time():
    assert samples_at(50, 50.0) == 50 and samples_at(10, 50.0) == 10
    assert samples_at(50, 500.0) == 500 and samples_at(10, 100.0) == 20
    assert samples_at(50, 25.0) == 25 and samples_at(10, float("nan")) == 10


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_faster_imu_gives_the_same_steps_and_turns(seed):
    s = simulate("office2f", "normal", seed).session
    p = Params()
    steps = detect_steps(s.accelerometer, p.steps)
    # the realistic walker's shuffles and short steps are missed at any rate
    assert (
        abs(len(steps) - s.metadata.extra["true_step_count"])
        <= 0.1 * s.metadata.extra["true_step_count"]
    )
    base = detect_landmarks(steps, estimate_heading(s, p.heading), s.pressure, p)
    for hz in (200.0, 500.0):
        fast = replace(
            s,
            accelerometer=_resampled(s.accelerometer, hz),
            gyroscope=_resampled(s.gyroscope, hz),
        )
        st = detect_steps(fast.accelerometer, p.steps)
        assert abs(len(st) - len(steps)) <= 0.01 * len(steps), (hz, len(st), len(steps))
        d = detect_landmarks(st, estimate_heading(fast, p.heading), fast.pressure, p)
        for kind in ("gyro", "acc"):
            assert abs(d.count(kind) - base.count(kind)) <= 1, (hz, kind)
