"""The simulator's RSS drift (an Ornstein–Uhlenbeck process per AP, workstation/sim/wifi.py):
the vectorized form equals the recursion it unrolls, and has the stated variance and
correlation time."""

import numpy as np

from workstation.sim.wifi import REALISTIC, drift


def _recursive(t, e, sd, tau):
    out = np.empty_like(e)
    out[0] = sd * e[0]
    for k in range(1, t.size):
        a = np.exp(-(t[k] - t[k - 1]) / tau)
        out[k] = a * out[k - 1] + sd * np.sqrt(1 - a * a) * e[k]
    return out


def test_drift_is_the_recursion_unrolled():
    """Irregular scan times over 3 h (several restarts of the cumulative sum)."""
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.5, 60.0, 800))
    got = drift(t, 5, REALISTIC, np.random.default_rng(1))
    e = np.random.default_rng(1).standard_normal((t.size, 5))
    want = _recursive(t, e, REALISTIC.drift_sd_db, REALISTIC.drift_tau_s)
    assert np.allclose(got, want, atol=1e-9)


def test_drift_has_its_variance_and_correlation_time():
    """Over 200 APs × 3,000 scans 2 s apart: σ and the lag-τ correlation e^-1 within sampling
    error (a few per cent)."""
    spec = REALISTIC
    t = np.arange(3000) * 2.0
    x = drift(t, 200, spec, np.random.default_rng(2))
    assert abs(x.std() / spec.drift_sd_db - 1) < 0.05
    lag = int(round(spec.drift_tau_s / 2.0))
    r = np.mean(x[lag:] * x[:-lag]) / x.var()
    assert abs(r - np.exp(-1)) < 0.05
