"""The realistic simulator against the real walks (issue #12): every quantity of the table,
measured by the same code (workstation/sim/realism.py), lies in the real walks' range."""

import math

import numpy as np
import pytest

from tests.conftest import IPIN, need
from workstation.sim import simulate
from workstation.sim.realism import REAL_RANGES, measure

# the real ranges come from 10 walks (4 for the compass): a single simulated walk may fall
# outside them by this share of the range's width on either side; the median may not
TOLERANCE = 0.25


def _outside(m: dict, tolerance: float = TOLERANCE) -> dict:
    bad = {}
    for k, (lo, hi) in REAL_RANGES.items():
        w = tolerance * (hi - lo)
        v = m.get(k, math.nan)
        if not (lo - w <= v <= hi + w):
            bad[k] = (v, (lo, hi))
    return bad


@pytest.fixture(scope="module")
def realistic_walks():
    return {
        (w, seed): measure(simulate("office2f", w, seed).session)
        for w in ("normal", "heldout")
        for seed in (1, 2, 3)
    }


def test_realistic_walks_lie_in_the_real_ranges(realistic_walks):
    """The median over six simulated walks lies in every real range; single walks may stray (by
    up to a quarter of the range's width) as single real walks do — ten real walks span about
    their 5th–95th percentiles — but not more than one quantity in ten."""
    keys = list(REAL_RANGES)
    med = {k: float(np.median([m[k] for m in realistic_walks.values()])) for k in keys}
    assert not _outside(med, 0.0), _outside(med, 0.0)
    strays = {key: _outside(m) for key, m in realistic_walks.items()}
    n_bad = sum(len(v) for v in strays.values())
    assert n_bad <= 0.1 * len(keys) * len(realistic_walks), strays


def test_the_ideal_model_does_not(realistic_walks):
    """The clean model is far outside on the quantities the issue names (a check that the test
    above can fail)."""
    m = measure(simulate("office2f", "normal", 1, model="ideal").session)
    bad = _outside(m)
    for k in ("yaw_rate_rms_straight", "step_change", "still_fraction", "distinct_aps"):
        assert k in bad, (k, m[k])


@pytest.mark.shared_data
def test_real_ranges_are_what_the_real_walks_measure():
    from workstation.session import load_session

    logs = sorted(need(IPIN / "logfiles").glob("*.txt"))
    got = [measure(load_session(f)) for f in logs]
    for k, (lo, hi) in REAL_RANGES.items():
        v = [g[k] for g in got if not math.isnan(g[k])]
        assert min(v) == pytest.approx(lo, rel=2e-3, abs=1e-4), k
        assert max(v) == pytest.approx(hi, rel=2e-3, abs=1e-4), k


def test_realism_command_prints_the_table(capsys):
    from tests.conftest import REPO
    from workstation.cli import main

    assert main(["realism", str(REPO / "sample_sessions" / "office2f" / "normal")]) == 0
    out = capsys.readouterr().out
    assert "yaw_rate_rms_straight" in out and "outside the range" in out
