"""Distances to segments (``geo.distance_to_segments``): the plane geometry against hand-worked
cases, and its two ways (every segment at once for a few points, a loop over the segments for
many) giving the same bits on random layouts."""

import numpy as np
import pytest

import workstation.geo as geo
from workstation.geo import distance_to_segments


def test_hand_worked_distances():
    segs = [[[0, 0], [10, 0]], [[20, 5], [20, 5]]]  # a corridor along x, and a point
    x, y = np.array([5.0, -3.0, 13.0, 20.0, 5.0]), np.array([2.0, 4.0, 0.0, 9.0, 0.0])
    want = [2.0, 5.0, 3.0, 4.0, 0.0]  # beside, past the end (3-4-5), past the end, the point, on
    assert distance_to_segments(x, y, segs) == pytest.approx(want)
    assert np.isinf(distance_to_segments(x, y, [])).all()
    assert distance_to_segments([], [], segs).shape == (0,)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_both_ways_give_the_same_bits(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n, s = rng.integers(1, geo.FEW_POINTS + 1), rng.integers(1, 400)
    x, y = rng.normal(0, 60, (2, n))
    segs = rng.normal(0, 60, (s, 2, 2))
    segs[: s // 10, 1] = segs[: s // 10, 0]  # some of no length
    at_once = distance_to_segments(x, y, segs)
    monkeypatch.setattr(geo, "FEW_POINTS", 0)
    assert np.array_equal(at_once, distance_to_segments(x, y, segs))
