"""Backward correction (replay.bend): a closed segment rotated and scaled about its start so that
it ends on the landmark that closes it."""

import numpy as np

from workstation.pipeline.tracking.replay import bend


def test_bend_lands_the_end_on_the_landmark_and_keeps_the_shape():
    for seed in range(5):
        rng = np.random.default_rng(seed)
        ax, ay = rng.uniform(-50, 50, 2)
        px = ax + np.cumsum(rng.normal(0.6, 0.2, 40))
        py = ay + np.cumsum(rng.normal(0.0, 0.2, 40))
        ex, ey = px[-1], py[-1]
        vx, vy = ex + rng.normal(0, 3), ey + rng.normal(0, 3)
        bx, by = bend(px, py, ax, ay, ex, ey, vx, vy)
        assert np.hypot(bx[-1] - vx, by[-1] - vy) < 1e-9
        # a similarity about the start: every distance from it scales by one factor
        s = np.hypot(vx - ax, vy - ay) / np.hypot(ex - ax, ey - ay)
        assert np.allclose(np.hypot(bx - ax, by - ay), s * np.hypot(px - ax, py - ay))


def test_a_tiny_walked_displacement_is_shifted_linearly():
    px, py = np.array([0.1, 0.2, 0.3]), np.zeros(3)
    bx, by = bend(px, py, 0.0, 0.0, 0.3, 0.0, 0.3, 2.0)
    assert np.allclose(by, [2 / 3, 4 / 3, 2.0]) and np.allclose(bx, px)
