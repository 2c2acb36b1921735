"""The floor from pressure (eq. 9), with floors as they are built.

Eq. 9 assumes floors evenly spaced p_d apart. Real buildings are not (the IPIN museum's floors
are 0.37 and 0.28 hPa apart), and one flight of stairs may span two floors. Here each pair of
neighbouring floors has its own spacing (hPa of pressure fall going up): given by the building
(``known``), or learnt from the walk whenever a floor change is matched, with p_d as the prior
for the spacings not yet seen.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

# σ of log(observed / predicted climb) over spacings not measured yet: storey heights run from
# ~2.4 to ~6 m while p_d = 0.45 hPa is ~3.7 m.
PRIOR_SPREAD = 0.3
# σ of pressure differences measured a few seconds apart (noise, ventilation, door drafts)
PRESSURE_SD_HPA = 0.05


@dataclass(frozen=True)
class FloorModel:
    """Floors of the building and the pressure fall between neighbours; an anchor pressure."""

    floors: np.ndarray  # sorted floor numbers
    gaps: np.ndarray  # hPa between floors[i] and floors[i + 1] (> 0)
    known: np.ndarray  # bool per gap: given or measured (else the p_d prior)
    p_ref: float  # pressure at the anchor
    f_ref: float  # the anchor's floor

    @classmethod
    def prior(
        cls, floors: Sequence[float] | np.ndarray, p_d: float, p_ref: float, f_ref: float,
        given: dict[float, float] | None = None,
    ) -> FloorModel:  # fmt: skip
        """Spacing ``p_d`` per floor number between neighbours; ``given``: {floor: hPa level
        (pressure fall from a common datum)} for floors whose level the building states."""
        names = (
            set(np.asarray(floors, float).tolist()) | {float(f_ref)} | set(map(float, given or ()))
        )
        fl = np.array(sorted(names))
        gaps = np.diff(fl) * p_d
        known = np.zeros(gaps.size, bool)
        if given:
            for i in range(gaps.size):
                a, b = fl[i], fl[i + 1]
                if a in given and b in given:
                    gaps[i], known[i] = max(given[b] - given[a], 1e-3), True
        return cls(fl, gaps, known, float(p_ref), float(f_ref))

    @cached_property
    def heights(self) -> np.ndarray:
        """Pressure fall (hPa) from the lowest floor to each floor."""
        return np.concatenate([[0.0], np.cumsum(self.gaps)])

    @cached_property
    def _floor_list(self) -> list[float]:
        return self.floors.tolist()

    @cached_property
    def _height_list(self) -> list[float]:
        return self.heights.tolist()

    @cached_property
    def _floor_index(self) -> dict[float, int]:
        return {f: i for i, f in enumerate(self._floor_list)}

    def _index(self, f: float) -> int:
        i = self._floor_index.get(f)
        if i is not None:
            return i
        fl = self._floor_list
        return min(range(len(fl)), key=lambda i: abs(fl[i] - f)) if len(fl) > 1 else 0

    @cached_property
    def _gap_terms(self) -> tuple[list[float], list[float]]:
        """Per gap: hPa, and hPa × its log-ratio σ (0.1 measured, ``PRIOR_SPREAD`` not)."""
        g = self.gaps.tolist()
        return g, [x * (0.1 if k else PRIOR_SPREAD) for x, k in zip(g, self.known.tolist())]

    def nearest_floor(self, p: float) -> float:
        """:meth:`nearest` for one pressure (the tracker's hot path)."""
        if self.floors.size == 1:  # one floor (a walk without a barometer): nothing to choose
            return float(self.floors[0])
        h = self._height_list
        c = h[self._index(self.f_ref)] + (self.p_ref - float(p))
        best, bd = 0, abs(c - h[0])
        for i in range(1, len(h)):  # the first of equally near floors, as argmin
            d = abs(c - h[i])
            if d < bd:
                best, bd = i, d
        return self._floor_list[best]

    def climb(self, p: ArrayLike) -> np.ndarray:
        """Pressure fall from the anchor, in the heights' scale (eq. 9's p_ref − p)."""
        return self.heights[self._index(self.f_ref)] + (self.p_ref - np.asarray(p, float))

    def continuous(self, p: ArrayLike) -> np.ndarray:
        """Floor number (fractional) at pressures ``p``: eq. 9 with the spacings of this model."""
        h, fl = self.heights, self.floors
        c = self.climb(p)
        if fl.size == 1:
            return np.full(np.shape(c), fl[0]) + 0 * c
        lo = fl[0] + (c - h[0]) * (fl[1] - fl[0]) / self.gaps[0]
        hi = fl[-1] + (c - h[-1]) * (fl[-1] - fl[-2]) / self.gaps[-1]
        return np.where(c < h[0], lo, np.where(c > h[-1], hi, np.interp(c, h, fl)))

    def nearest(self, p: ArrayLike) -> np.ndarray:
        """The building's floor nearest the pressure-derived level."""
        c = self.climb(p)
        return self.floors[np.abs(np.asarray(c)[..., None] - self.heights).argmin(axis=-1)]

    def change_loglik(self, dp: float, f_from: float, f_to: float) -> float:
        """Log-likelihood (up to a constant) of a pressure change ``dp`` (hPa, + = down) over
        a floor change from ``f_from`` to ``f_to``: the ratio of the observed climb to the
        expected one is log-normal, σ = ``PRIOR_SPREAD`` for spacings not measured yet (storeys
        of 2.5-6 m), 0.1 for measured ones, widened by the pressure noise; −inf when the
        direction is wrong."""
        i, j = self._index(f_from), self._index(f_to)
        lo, hi = min(i, j), max(i, j)
        gaps, spreads = self._gap_terms
        expected = sum(gaps[lo:hi])
        climb = -dp if j > i else dp  # pressure falls going up
        if expected <= 0 or climb <= 0:
            return -math.inf
        spread = sum(spreads[lo:hi]) / expected
        sd = math.hypot(spread, PRESSURE_SD_HPA / expected)
        return -0.5 * (math.log(climb / expected) / sd) ** 2

    def moved(self, p_now: float, f_now: float) -> FloorModel:
        """Re-anchored at a landmark on floor ``f_now`` with pressure ``p_now`` (takes drift out)."""
        return replace(self, p_ref=float(p_now), f_ref=float(f_now))

    def learned(self, p_from: float, f_from: float, p_to: float, f_to: float) -> FloorModel:
        """The spacings between ``f_from`` and ``f_to`` re-estimated from a matched floor change
        (measured pressures at both ends); the unknown ones take the measured climb in proportion
        to their prior, the known ones keep theirs unless all are unknown."""
        i, j = self._index(f_from), self._index(f_to)
        lo, hi = min(i, j), max(i, j)
        climb = abs(p_from - p_to)
        gaps, known = self.gaps.copy(), self.known.copy()
        seg = slice(lo, hi)
        free = ~known[seg]
        if hi > lo and climb > 0:
            if free.any():
                rest = climb - gaps[seg][~free].sum()
                if rest > 0.2 * gaps[seg][free].sum():
                    gaps[seg][free] *= rest / gaps[seg][free].sum()
                    known[seg] = True
        return replace(self, gaps=gaps, known=known, p_ref=float(p_to), f_ref=float(f_to))
