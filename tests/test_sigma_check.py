"""σ's equation from its terms, and the check of σ on walks its constants were not chosen on
(issue #29: "σ rank-correlates with the true placement error … on walks it was not fitted on")."""

import numpy as np
import pytest

from workstation.evaluate.sigma_check import GRID, held_out
from workstation.pipeline.sigma import Shape, Terms, sigma_of


def _terms(rng, n: int) -> Terms:
    closed = rng.random(n) < 0.7
    return Terms(
        walking=rng.random(n) < 0.95,
        closed=closed,
        spread0=np.where(rng.random(n) < 0.2, rng.uniform(0, 6, n), 0.0),
        spread1=np.where(closed & (rng.random(n) < 0.2), rng.uniform(0, 6, n), 0.0),
        d_prev=rng.uniform(0, 40, n),
        d_next=np.where(closed, rng.uniform(0, 40, n), 0.0),
        correction=rng.exponential(1.5, n),
        at=rng.random(n) < 0.1,
        compass=np.zeros(n),
    )


def test_sigma_of_is_the_modules_equation():
    t = Terms(
        walking=np.array([True, True, True, False]),
        closed=np.array([True, False, True, True]),
        spread0=np.array([0.0, 0.0, 2.0, 0.0]),
        spread1=np.array([0.0, 0.0, 0.0, 0.0]),
        d_prev=np.array([10.0, 10.0, 1.0, 1.0]),
        d_next=np.array([4.0, 0.0, 30.0, 1.0]),
        correction=np.array([0.0, 0.0, 5.0, 0.0]),
        at=np.array([False, False, True, False]),
        compass=np.zeros(4),
    )
    k = Shape()
    s = sigma_of(t, k)
    assert s[0] == pytest.approx(k.scale * np.hypot(k.base_m, k.drift * 4.0))  # the nearer: end
    # open: drift counts double
    assert s[1] == pytest.approx(k.scale * np.hypot(k.base_m, k.open_factor * k.drift * 10.0))
    # on a landmark: with its spread
    assert s[2] == pytest.approx(k.scale * np.hypot(max(k.at_landmark_m, k.base_m), 2.0))
    assert np.isinf(s[3])  # before the walk started
    t2 = t._replace(at=np.zeros(4, bool))
    closed_far = sigma_of(t2, k)[2]  # the start's spread (2 m), and the correction beyond free
    assert closed_far == pytest.approx(k.scale * (np.hypot(k.base_m, np.hypot(2.0, k.drift))
                                       + k.correction_weight * (5.0 - k.correction_free_m)))
    # a graph whose landmarks are known only to 1.5 m (one from taps): every σ starts there
    wide = sigma_of(t, k.landmarks(1.5))
    assert wide[0] == pytest.approx(k.scale * np.hypot(1.5, k.drift * 4.0))
    assert wide[2] == pytest.approx(k.scale * np.hypot(1.5, 2.0))
    assert np.all(wide[:3] > s[:3])
    assert k.landmarks(None) == k


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_held_out_finds_a_sigma_that_predicts_and_none_that_does_not(seed):
    """Errors drawn as |N(0, σ)| about a σ of one of the grid's shapes: on the held-out halves
    σ ranks them as well as the true shape does (within sampling noise); errors that σ does
    not predict give a held-out figure near 0."""
    rng = np.random.default_rng(seed)
    truth = GRID[int(rng.integers(len(GRID)))]
    walks, noise = [], []
    for _ in range(30):
        t = _terms(rng, 40)
        s = sigma_of(t, truth)
        e = np.abs(rng.normal(0.0, np.where(np.isfinite(s), s, 1.0)))
        walks.append((t, e))
        noise.append((t, rng.exponential(2.0, 40)))
    from scipy.stats import spearmanr

    allt = Terms(*(np.concatenate([w[0][k] for w in walks]) for k in range(len(Terms._fields))))
    alle = np.concatenate([w[1] for w in walks])
    s = sigma_of(allt, truth)
    ideal = spearmanr(s[np.isfinite(s)], alle[np.isfinite(s)]).statistic
    h, none = held_out(walks, seed=seed), held_out(noise, seed=seed)
    assert h is not None and none is not None
    assert h.fits == 10 and ideal > 0.4
    assert h.rank_correlation_mean > ideal - 0.1
    assert abs(none.rank_correlation_mean) < 0.15


def test_held_out_needs_walks():
    rng = np.random.default_rng(0)
    assert held_out([(_terms(rng, 10), rng.random(10)) for _ in range(3)]) is None
    assert Shape() in GRID  # the defaults are among the shapes the check chooses from
