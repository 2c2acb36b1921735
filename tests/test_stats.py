"""stats.error_stats, the one statistics function: values worked by hand."""

import numpy as np
import pytest

from workstation.stats import FLOOR_PENALTY_M, error_stats


def test_horizontal_statistics():
    s = error_stats([4.0, 1.0, 3.0, 2.0, np.nan])  # NaN (not placed) left out without floors
    assert s == {"mean_m": 2.5, "median_m": 2.5, "p75_m": 3.25, "p90_m": 3.7}


def test_a_wrong_floor_costs_15_m_per_floor_in_the_mean_and_the_evaal_score():
    e, fe = np.array([1.0, 2.0, 3.0, 4.0]), np.array([0.0, 0.0, 1.0, -2.0])
    s = error_stats(e, fe, prefix="q")
    pen = e + FLOOR_PENALTY_M * np.abs(fe)  # 1, 2, 18, 34
    assert s["q_floor_accuracy"] == 0.5
    assert s["q_mean_with_floor_penalty_m"] == pytest.approx(13.75)
    assert s["q_evaal_p75_m"] == pytest.approx(np.percentile(pen, 75)) == pytest.approx(22.0)
    assert s["q_mean_m"] == 2.5  # the horizontal part alone


def test_nothing_to_score():
    assert error_stats([]) == {} and error_stats([np.nan]) == {}
