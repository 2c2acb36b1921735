"""Matchers: how a scan is matched against the radio map (issue #63) — one table of named
methods, each a fingerprint representation, a distance, k and how the k neighbours are
averaged. The paper's (§V-C) is ``1nn``: positive values (eq. 21), Euclidean, the nearest
reference point's position.

- **Powed** representation (Torres-Sospedra et al. 2015, "Comprehensive analysis of distance
  and similarity measures for Wi-Fi fingerprinting indoor positioning systems"): eq. 21's
  positive value v = RSS − min scaled to (0, 1] by −min and raised to ``POWED_BETA`` = e,
  (v / −min)^β — a strong reading weighs far more than a weak one, whose level phones report
  least alike.
- **Sørensen** (Bray–Curtis) distance: Σ|q − r| / Σ(q + r), bounded in [0, 1]: an AP heard by one
  side only costs in proportion to its level, not its square.
- **Weighted kNN**: the position is the mean of the k nearest reference points weighted by
  1 / (distance + ``WEIGHT_EPS``); the floor is the nearest one's.

The default (``DEFAULT``) was chosen on the four mall floors, the museum and UJIIndoorLoc
together (docs/experiments.md, "Matchers"); a map built by the walks is checked against the
tap oracle under the *same* matcher (``evaluate --walks``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workstation.vocabularies import MetricName, Representation, Weights

POWED_BETA = math.e  # the exponent of the powed representation (Torres-Sospedra et al.)
WEIGHT_EPS = 1e-3  # added to a distance before it is inverted into a weight


# the vocabularies: workstation/vocabularies.py (the parameters offer them as choices)


@dataclass(frozen=True)
class Matcher:
    """A representation, a distance, k and the averaging of the k nearest."""

    metric: MetricName = "euclidean"
    k: int = 1
    representation: Representation = "positive"
    weights: Weights = "equal"

    def words(self) -> str:
        """The matcher in a few words, e.g. "5-NN weighted, Sørensen, powed"."""
        nn = f"{self.k}-NN" + (" weighted" if self.weights == "inverse-distance" and self.k > 1
                               else "")  # fmt: skip
        metric = "Sørensen" if self.metric == "sorensen" else "Euclidean"
        return f"{nn}, {metric}, {self.representation}"


#: the named methods ``--method`` picks from (the first is the paper's)
METHODS: dict[str, Matcher] = {
    "1nn": Matcher(),
    "knn": Matcher(k=3),
    "sorensen": Matcher(metric="sorensen"),
    "powed-sorensen": Matcher(metric="sorensen", representation="powed"),
    "powed-sorensen-5nn": Matcher("sorensen", 5, "powed", "inverse-distance"),
    "powed-sorensen-13nn": Matcher("sorensen", 13, "powed", "inverse-distance"),
}
DEFAULT = "powed-sorensen-5nn"
PAPER = "1nn"


def of_params(lp) -> Matcher:
    """The matcher a :class:`~workstation.params.LocalizeParams` selects (its fields typed with
    the same vocabularies)."""
    return Matcher(lp.metric, int(lp.k), lp.representation, lp.weights)


def name_of(m: Matcher) -> str:
    """The method's name in :data:`METHODS`, or its words when it has none."""
    return next((n for n, v in METHODS.items() if v == m), m.words())


def powed(pos: np.ndarray, rss_min: float) -> np.ndarray:
    """The powed representation of positive values ``pos`` (eq. 21 with minimum ``rss_min``):
    (pos / −rss_min)^β, 0 where unheard."""
    return (np.maximum(pos, 0.0) / max(-rss_min, 1e-9)) ** POWED_BETA


def weighted_mean(values: np.ndarray, dist: np.ndarray, weights: str) -> np.ndarray:
    """Per row, the mean of ``values`` (Q, k): plain, or weighted by 1 / (distance + ε)."""
    if weights != "inverse-distance" or values.shape[1] == 1:
        return values.mean(axis=1)
    w = 1.0 / (dist + WEIGHT_EPS)
    return (values * w).sum(axis=1) / w.sum(axis=1)
