"""Floor-change detection (eq. 4–6) on pressure made of level stretches and ramps: where the
entries and exits fall, and a flight broken by a landing or by one window of noise. Changes are
read between 1-s window means, so a ramp's ends lose up to a window's share of it (ATOL)."""

import numpy as np
import pytest

from workstation.params import BaroLandmarkParams
from workstation.pipeline.landmarks import BRIDGE_LEVELS, detect_baro
from workstation.session import Scalar

HZ = 25.0
ATOL = 0.06  # hPa


def pressure(*legs: tuple[float, float]) -> Scalar:
    """Legs of (seconds, hPa change over them), from 1000 hPa: 0 hPa is a level stretch."""
    t, v, t0, p0 = [], [], 0.0, 1000.0
    for dur, dp in legs:
        tt = t0 + np.arange(int(round(dur * HZ))) / HZ
        t.append(tt)
        v.append(p0 + dp * (tt - t0) / dur)
        t0, p0 = t0 + dur, p0 + dp
    return Scalar(np.concatenate(t), np.concatenate(v))


def changes(s: Scalar):
    """(kind, time, change, start time) of every detection, default parameters."""
    return [(k, t, v, ts) for t, k, _, v, ts in detect_baro(s, BaroLandmarkParams())]


def kinds(got):
    return [k for k, *_ in got]


def test_one_flight_is_an_entry_and_an_exit():
    got = changes(pressure((20, 0), (12, 0.4), (20, 0)))
    assert kinds(got) == ["baro_entry", "baro_exit"]
    (_, t_in, v, ts), (_, t_out, v2, ts2) = got
    assert abs(t_in - 20) <= 1 and abs(t_out - 32) <= 1 and ts == ts2 == t_in
    assert v == v2 and abs(v - 0.4) < ATOL


@pytest.mark.parametrize("landing_s", [8.0, 12.0])
def test_a_flight_broken_by_a_long_landing_is_also_one_change(landing_s):
    """Parts of 0.3 and 0.15 hPa (ε_baro2 = 0.2) around a landing longer than max_level_s:
    the first part is a change alone; the whole flight is one more candidate — an exit at the
    end, started where the flight started — and the first part's entry is not repeated."""
    end = 20 + 6 + landing_s + 5
    got = changes(pressure((20, 0), (6, 0.3), (landing_s, 0), (5, 0.15), (20, 0)))
    assert kinds(got).count("baro_entry") == 1
    exits = [(t, v, ts) for k, t, v, ts in got if k == "baro_exit"]
    assert len(exits) == 2
    (t1, v1, s1), (t2, v2, s2) = exits
    assert abs(t1 - 26) <= 1 and abs(v1 - 0.3) < ATOL  # the first part alone
    assert abs(t2 - end) <= 1 and abs(v2 - 0.45) < ATOL and s2 == s1  # the whole flight


def test_a_flight_broken_by_one_noisy_window_is_one_change():
    """One window against the sign (a draft, a door) splits 0.19 + 0.2 hPa into two runs that
    are neither a change alone; together they are."""
    got = changes(pressure((20, 0), (9, -0.19), (1, 0.03), (9, -0.2), (20, 0)))
    assert kinds(got) == ["baro_entry", "baro_exit"]
    assert abs(got[0][2] + 0.36) < ATOL and abs(got[0][1] - 20) <= 1 and abs(got[1][1] - 39) <= 1


def test_separate_small_changes_are_not_joined():
    """Two 0.15-hPa drifts far apart (weather, a ramp) are no floor change; a small run next to
    a change of the other sign is not part of it."""
    far = BRIDGE_LEVELS * BaroLandmarkParams().max_level_s + 10
    assert changes(pressure((20, 0), (5, 0.15), (far, 0), (5, 0.15), (20, 0))) == []
    got = changes(pressure((20, 0), (5, 0.15), (8, 0), (8, -0.3), (20, 0)))
    assert kinds(got) == ["baro_entry", "baro_exit"] and all(v < 0 for _, _, v, _ in got)


def test_two_flights_each_a_change_alone_are_not_joined():
    got = changes(pressure((20, 0), (8, 0.35), (10, 0), (8, 0.3), (20, 0)))
    assert kinds(got) == ["baro_entry", "baro_exit", "baro_entry", "baro_exit"]
    assert got[0][3] == got[1][3] and got[2][3] == got[3][3] and got[2][3] > got[1][1]
