"""Eq. 10 weighed (``tracker.fuse_step_length``): at the equation and on simulated walks against
the simulator's step length."""

import numpy as np
import pytest

from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.confidence import distance_sd
from workstation.pipeline.tracking.tracker import fuse_step_length
from workstation.sim import simulate
from workstation.sim.building import office2f
from workstation.sim.styles import STYLES

P = Params().pdr


def test_without_a_prior_spread_each_path_replaces_the_length_as_printed():
    p = Params().updated(**{"pdr.step_length_sd_m": 0.0}).pdr
    assert fuse_step_length(0.63, 0.0, 20.0, 25, p) == (pytest.approx(0.8), 0.0)
    assert fuse_step_length(0.63, 0.0, 20.0, 10, p)[0] == p.max_step_length_m  # clamped


def test_the_update_is_the_kalman_gain_on_the_distance_terms_sigma():
    var0 = P.step_length_sd_m**2
    sd_m = distance_sd(30.0, P.confidence_threshold, P.step_length_cv) / 40
    gain = var0 / (var0 + sd_m**2)
    length, var = fuse_step_length(0.63, var0, 30.0, 40, P)
    assert length == pytest.approx(0.63 + gain * (0.75 - 0.63))
    assert var == pytest.approx((1 - gain) * var0)
    assert 0.63 < length < 0.75 and var < var0


def test_a_short_path_moves_the_length_less_than_a_long_one_of_the_same_pace():
    var0 = P.step_length_sd_m**2
    short, _ = fuse_step_length(0.63, var0, 9.0, 10, P)
    long_, _ = fuse_step_length(0.63, var0, 45.0, 50, P)
    assert 0.63 < short < long_ < 0.9


def test_agreeing_paths_add_up_as_independent_measurements():
    var0, n = P.step_length_sd_m**2, 12
    var_m = (distance_sd(21.6, P.confidence_threshold, P.step_length_cv) / 30) ** 2
    length, var = 0.63, var0
    for _ in range(n):
        length, var = fuse_step_length(length, var, 21.6, 30, P)  # 0.72 m a step
    info = 1 / var0 + n / var_m
    assert var == pytest.approx(1 / info)
    assert length == pytest.approx((0.63 / var0 + n * 0.72 / var_m) / info)
    assert 0.70 < length < 0.72


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_on_simulated_walks_the_length_lies_nearer_the_walkers_than_eq_10_as_printed(seed):
    """The 'heldout' walker steps 0.72 m, the initial length is 0.63 m. After the first
    calibration the weighed length is nearer it on average than eq. 10 as printed (which
    follows each path's error), and ends within half the prior spread of it."""
    b = office2f()
    sim = simulate(b, "heldout", seed, "realistic")
    truth = STYLES["heldout"].step_len_m
    dev = {}
    for sd in (P.step_length_sd_m, 0.0):
        # the 'heldout' walk follows the 'reverse' route (sim/__init__.py): its start is that
        # route's first landmark (it was the survey's, 1–2 corridors off, until session 17)
        start = {"pdr.step_length_sd_m": sd, "pdr.start_node": b.routes["reverse"][0]}
        p = Params().updated(**start)
        run = Pipeline(sim.session, sim.graph, p).run()
        length = run.track.steps.step_length
        after = length[np.argmax(length != P.initial_step_length_m):]
        dev[sd] = float(np.mean(np.abs(after - truth)))
        if sd:
            assert abs(float(after[-1]) - truth) < P.step_length_sd_m / 2
            assert run.summary().to_json()["step_length_m"] == round(float(length[-1]), 3)
    assert dev[P.step_length_sd_m] < dev[0.0]
