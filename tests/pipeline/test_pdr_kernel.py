"""The PDR kernel (pipeline/pdr.py, eq. 7–8 and the gyro's alignment to the compass), the one
place the tracker, its plain-PDR trace and the PDR baselines take them from."""

import numpy as np
import pytest

from workstation.pipeline.pdr import ALIGN_STEPS, dead_reckon, gyro_offset


def test_dead_reckoning_is_eq_7_8():
    # a 4 × 4-step square of 0.7-m steps comes back to its start
    theta = np.repeat([0.0, np.pi / 2, np.pi, -np.pi / 2], 4)
    x, y = dead_reckon(2.0, -1.0, 0.7, theta)
    assert (x[3], y[3]) == pytest.approx((2.0 + 4 * 0.7, -1.0))
    assert (x[-1], y[-1]) == pytest.approx((2.0, -1.0), abs=1e-12)
    # per-step lengths: the sum of l_j (cos θ_j, sin θ_j)
    rng = np.random.default_rng(0)
    th, ln = rng.uniform(-np.pi, np.pi, 50), rng.uniform(0.4, 0.9, 50)
    x, y = dead_reckon(0.0, 0.0, ln, th)
    assert x[-1] == pytest.approx(np.sum(ln * np.cos(th)))
    assert y[-1] == pytest.approx(np.sum(ln * np.sin(th)))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_gyro_offset_is_recovered_within_the_compass_noise(seed):
    """Compass = truth + N(0, 10°), gyro = truth − offset: the offset from the first 15 steps
    is within 3 σ/√15 ≈ 8° of the truth; steps after the first 15 are not used."""
    rng = np.random.default_rng(seed)
    truth = np.cumsum(rng.normal(0, 0.05, 40))
    offset = rng.uniform(-np.pi, np.pi)
    gyro = truth - offset
    compass = truth + rng.normal(0, np.radians(10), 40)
    compass[ALIGN_STEPS:] += 2.0  # a magnetic disturbance later on changes nothing
    err = np.angle(np.exp(1j * (gyro_offset(compass, gyro) - offset)))
    assert abs(np.degrees(err)) < 3 * 10 / np.sqrt(ALIGN_STEPS)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_baselines_floor_is_eq_9_through_the_trackers_floor_model(seed):
    """baselines.pdr.floors takes eq. 9 from FloorModel: floor = f₀ − (p − p₀)/p_d, rounded to
    the nearest known floor (or to an integer when none is given); no barometer: the start's."""
    from types import SimpleNamespace

    from workstation.baselines.pdr import floors
    from workstation.session import Scalar

    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 100.0, 400)
    p = 1000.0 - np.cumsum(rng.normal(0, 0.02, t.size))  # a walk climbing and descending
    s = SimpleNamespace(pressure=Scalar(t, p))
    f0, p_d = float(rng.integers(-2, 3)), 0.45
    expect = f0 - (p - p[0]) / p_d
    rounded, cont = floors(s, t, f0, p_d, continuous=True)
    assert cont == pytest.approx(expect, abs=1e-9)
    assert np.array_equal(rounded, np.round(expect))
    known = f0 + np.array([-4.0, -2.0, 0.0, 2.0, 4.0])  # every other floor, the start among them
    rounded = floors(s, t, f0, p_d, known)
    assert np.array_equal(rounded, known[np.abs(expect[:, None] - known).argmin(axis=1)])
    none = floors(SimpleNamespace(pressure=None), t, f0, p_d, known)
    assert np.array_equal(none, np.full(t.size, f0))


def test_one_step_of_many_hypotheses_is_the_last_row_of_dead_reckoning():
    """pdr.step (the particle filters) and dead_reckon are one equation: a walk reckoned step
    by step with step() ends where dead_reckon puts it."""
    from workstation.pipeline.pdr import step

    rng = np.random.default_rng(4)
    th, ln = rng.uniform(-np.pi, np.pi, 30), rng.uniform(0.4, 0.9, 30)
    x, y = np.array([1.0]), np.array([-2.0])
    for t, length in zip(th, ln):
        x, y = step(x, y, length, t)
    ex, ey = dead_reckon(1.0, -2.0, ln, th)
    assert (x[0], y[0]) == pytest.approx((ex[-1], ey[-1]), abs=1e-9)
