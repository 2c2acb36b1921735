"""Turns slower than ε_gyro (beyond the paper, ``gyro.slow_turn_deg``): mall walkers turned
70–90° at corners with the rate peaking at 0.8–1.05 rad/s, under Table I's 1.1, and 13 of the
15 walks that matched nothing had no detection at all. A slow turn counts when the heading
changes by at least 60°; a sway of the same rate does not."""

import numpy as np
import pytest

from workstation.params import Params
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import detect_gyro


def _heading(turns, rng, fs=50.0, t_end=40.0, sway_deg=0.0):
    """Heading from smooth turns [(t_mid, angle_deg, seconds)], noise on the rate."""
    t = np.arange(0, t_end, 1 / fs)
    rate = np.zeros_like(t)
    for tm, deg, dur in turns:  # a raised-cosine rate pulse integrating to deg
        m = np.abs(t - tm) < dur / 2
        rate[m] += np.radians(deg) / dur * (1 + np.cos(2 * np.pi * (t[m] - tm) / dur))
    if sway_deg:  # step-synchronous sway, ±sway_deg at 0.9 Hz
        rate += np.radians(sway_deg) * 2 * np.pi * 0.9 * np.cos(2 * np.pi * 0.9 * t)
    rate += rng.normal(0, 0.03, t.size)
    gyro = np.concatenate([[0.0], np.cumsum((rate[1:] + rate[:-1]) / 2 / fs)])
    return Heading(t, rate, gyro, np.full(t.size, np.nan))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_slow_right_angle_turn_is_a_landmark_and_a_sway_is_not(seed):
    rng = np.random.default_rng(seed)
    p = Params().gyro
    # 90° over 3.5 s: the rate peaks at 2·(π/2)/3.5 = 0.9 rad/s, under ε_gyro = 1.1
    slow = _heading([(10.0, 90.0, 3.5), (25.0, -75.0, 3.0)], rng)
    assert np.abs(slow.vertical_rate).max() < p.threshold_rad_s + 0.15
    got = detect_gyro(slow, p)
    assert len(got) == 2
    assert abs(got[0][0] - 10.0) < 1.0 and abs(got[1][0] - 25.0) < 1.0
    # the angle is measured where the rate is above ε_gyro/3: a slow turn's tails are cut
    assert np.degrees(got[0][3]) == pytest.approx(90, abs=18)
    assert np.degrees(got[1][3]) == pytest.approx(-75, abs=18)
    paper = type(p)(**{**p.__dict__, "slow_turn_deg": 0.0})
    assert detect_gyro(slow, paper) == []  # Table I's rate rule alone misses both
    # swaying ±10° at 0.9 Hz: the rate reaches 1.0 rad/s (between ε_gyro/2 and ε_gyro), the
    # heading never turns 60°; ±25°: 2.5 rad/s, and the wiggle rule drops it
    for deg in (10.0, 25.0):
        sway = _heading([], rng, sway_deg=deg)
        assert detect_gyro(sway, p) == [], deg
