"""How well σ (:mod:`..pipeline.sigma`) predicts the true placement error (issue #29): the
rank correlation and calibration table over every scan, and the same rank correlation on walks
σ's constants were not chosen on.

The held-out figure: the walks are halved at random; on one half the :data:`GRID` shape with
the highest rank correlation is chosen (as σ's constants were, on a small grid), and its rank
correlation on the other half is the figure; both halves in turn, ``HALVINGS`` times. A
rank statistic: only the constants' ratios matter, so the drift per metre stays fixed.
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from workstation.io.atomic import save_figure
from workstation.pipeline.sigma import Shape, Terms, sigma_of

SIGMA_BINS_M = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, np.inf)
RELIABILITY_K = tuple(round(0.25 * i, 2) for i in range(1, 13))
HALVINGS = 5
#: the shapes the held-out check chooses among (the defaults are one of them)
GRID = tuple(
    replace(Shape(), open_factor=o, correction_weight=w, at_landmark_m=a, base_m=b)
    for o, w, a, b in itertools.product(
        (1.0, 2.0, 3.0), (0.0, 0.5, 1.0), (0.3, 0.6), (0.25, 0.5, 1.0)
    )
)


@dataclass(frozen=True)
class SigmaBin:
    """One σ bin of the calibration table: its range, its scans, their mean / median error."""

    sigma_m: str  # "lo–hi"
    scans: int
    mean_error_m: float
    median_error_m: float


@dataclass(frozen=True)
class Calibration:
    """σ against the true placement error over a set of scans (:func:`sigma_calibration`)."""

    scans: int
    rank_correlation: float
    within_1_sigma: float
    within_2_sigma: float
    within_3_sigma: float
    bins: tuple[SigmaBin, ...]
    reliability: tuple[tuple[float, float], ...]  # (k, share within k σ)

    def words(self) -> str:
        """σ's calibration in a sentence: the share of points within 1σ, 2σ, 3σ of the truth (σ
        means the radius that holds 68 %: 60–75 % within 1σ and ≥ 90 % within 2σ is
        calibrated)."""
        return (
            f"σ calibration over the {self.scans} points our maps hold: "
            f"{100 * self.within_1_sigma:.1f} % within 1σ, {100 * self.within_2_sigma:.1f} % "
            f"within 2σ, {100 * self.within_3_sigma:.1f} % within 3σ (a σ that means what it "
            f"says: about 68 %, and 90 % or more within 2σ)"
        )

    def to_json(self) -> dict[str, Any]:
        return {"scans": self.scans, "rank_correlation": self.rank_correlation,
                "within_1_sigma": self.within_1_sigma, "within_2_sigma": self.within_2_sigma,
                "within_3_sigma": self.within_3_sigma, "bins": [asdict(b) for b in self.bins],
                "reliability": [list(c) for c in self.reliability]}  # fmt: skip


@dataclass(frozen=True)
class HeldOut:
    """σ's rank correlation on walks its shape was not chosen on (:func:`held_out`)."""

    halvings: int
    rank_correlation_mean: float
    rank_correlation_min: float
    defaults_chosen: int
    fits: int

    def words(self) -> str:
        """The held-out figure in a sentence (evaluate's output and results.md)."""
        return (
            f"On walks σ's constants were not chosen on (chosen on a random half of the walks, "
            f"checked on the other, {self.fits} times): rank correlation "
            f"{self.rank_correlation_mean} mean, {self.rank_correlation_min} at worst; the "
            f"defaults chosen {self.defaults_chosen} of {self.fits} times"
        )


@dataclass(frozen=True)
class SigmaCheck:
    """How well σ predicts the placement error (results.json's ``sigma_check``): over every
    scan on our trajectories (``scans``), on walks its shape was not chosen on (``held_out``),
    over the points our maps hold (``map_points``). None: too few scans or walks."""

    scans: Calibration | None = None
    held_out: HeldOut | None = None
    map_points: Calibration | None = None

    def to_json(self) -> dict[str, Any]:
        return {**(self.scans.to_json() if self.scans else {}),
                "held_out": asdict(self.held_out) if self.held_out else {},
                "map_points": self.map_points.to_json() if self.map_points else {}}  # fmt: skip


def sigma_calibration(se: np.ndarray) -> Calibration | None:
    """Rank correlation (Spearman) of σ with the placement error over scans with a finite σ,
    the share of scans within 1σ, 2σ and 3σ of the truth (σ means the radius holding 68 %:
    pipeline/sigma.py), and the calibration table: per σ bin, scans and mean / median error.
    None with fewer than three scans."""
    se = se[np.isfinite(se).all(axis=1)]
    if len(se) < 3:
        return None
    rho = _spearman(se[:, 0], se[:, 1])
    rows = []
    for lo, hi in zip(SIGMA_BINS_M, SIGMA_BINS_M[1:]):
        m = (se[:, 0] >= lo) & (se[:, 0] < hi)
        if m.any():
            rows.append(SigmaBin(f"{lo:g}–{hi:g}", int(m.sum()), round(float(se[m, 1].mean()), 3),
                                 round(float(np.median(se[m, 1])), 3)))  # fmt: skip
    # the reliability curve: the share within k σ for k = 0.25 … 3 (1σ, 2σ, 3σ among them)
    share = {k: float(np.mean(se[:, 1] <= k * se[:, 0])) for k in RELIABILITY_K}
    one, two, three = (round(share[k], 3) for k in (1, 2, 3))
    return Calibration(int(len(se)), round(rho, 3), one, two, three, tuple(rows),
                       tuple((k, round(v, 4)) for k, v in share.items()))  # fmt: skip


def _pooled(walks: list[tuple[Terms, np.ndarray]], idx) -> tuple[Terms, np.ndarray]:
    parts = [walks[i] for i in idx]
    terms = Terms(*(np.concatenate([t[k] for t, _ in parts]) for k in range(len(Terms._fields))))
    return terms, np.concatenate([e for _, e in parts])


def _spearman(sigma: np.ndarray, err: np.ndarray) -> float:
    from scipy.stats import spearmanr

    return float(spearmanr(sigma, err).statistic)


def _rho(terms: Terms, err: np.ndarray, shape: Shape) -> float:
    s = sigma_of(terms, shape)
    m = np.isfinite(s) & np.isfinite(err)
    if m.sum() < 3 or np.ptp(s[m]) == 0:
        return float("nan")
    return _spearman(s[m], err[m])


def held_out(walks: list[tuple[Terms, np.ndarray]], seed: int = 0) -> HeldOut | None:
    """σ's rank correlation on the half of the walks its shape was not chosen on (module doc).
    ``walks``: per walk, σ's terms and the true error of the same scans. {} with fewer than
    four walks."""
    if len(walks) < 4:
        return None
    rng = np.random.default_rng(seed)
    figures, chosen = [], []
    for _ in range(HALVINGS):
        order = rng.permutation(len(walks))
        half = len(walks) // 2
        for fit, test in ((order[:half], order[half:]), (order[half:], order[:half])):
            t_fit, e_fit = _pooled(walks, fit)
            scores = [_rho(t_fit, e_fit, g) for g in GRID]
            best = GRID[int(np.nanargmax(scores))]
            figures.append(_rho(*_pooled(walks, test), best))
            chosen.append(best == Shape())
    f = np.array(figures)
    return HeldOut(HALVINGS, round(float(np.nanmean(f)), 3), round(float(np.nanmin(f)), 3),
                   int(sum(chosen)), len(figures))


def reliability_figure(sc: Calibration | None, path) -> bool:
    """The reliability figure: the share of the map's points within k σ of the truth against
    k, beside what a σ that means what it says gives (a radial error whose 68 % radius is σ:
    1 − 0.32^(k²)) and the bars at 1σ (60–75 %) and 2σ (90 %). False when there is nothing to
    draw."""
    curve = sc.reliability if sc is not None else ()
    if sc is None or not curve:
        return False
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = np.array([c[0] for c in curve])
    share = np.array([c[1] for c in curve])
    kk = np.linspace(0, 3, 61)
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(kk, 1 - 0.32 ** (kk**2), color="0.6", ls="--", label="σ as it should be (68 % at 1σ)")
    ax.plot(k, share, "o-", color="C0", label=f"our map's {sc.scans} points")
    ax.fill_between([0.95, 1.05], 0.60, 0.75, color="C2", alpha=0.3, label="bars: 60–75 % at 1σ, ≥ 90 % at 2σ")
    ax.fill_between([1.95, 2.05], 0.90, 1.0, color="C2", alpha=0.3)
    ax.set_xlabel("k (distance to the truth in units of σ)")
    ax.set_ylabel("share of points within k σ")
    ax.set_title("Placement σ: reliability")
    ax.set_xlim(0, 3)
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
    return True
