"""The access points of several radio maps together (issue #66): what a merged map is over,
each map's columns in it and its phone's RSS offset (:mod:`.devices`). A map's readings over
the union are made when asked, block by block — a building's whole matrix (0.8 GB a copy at
40,000 rows × 2,400 APs) is made once by :meth:`.localize.Fingerprints.merge`, and never by
the joint estimate's links (:mod:`workstation.walks.joint`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from workstation.fingerprints.blocks import weakest
from workstation.fingerprints.devices import ap_means, fit_offsets, one_model


class _Map(Protocol):
    """What a union reads of a map (:class:`.localize.Fingerprints`)."""

    @property
    def bssids(self) -> np.ndarray: ...

    @property
    def rss(self) -> np.ndarray: ...

    @property
    def device(self) -> str: ...

    @property
    def on_standby(self) -> np.ndarray: ...


@dataclass(frozen=True)
class ApUnion:
    """The access points of several maps together (what :meth:`Fingerprints.merge` puts them
    over), each map's columns in it and its device offset: a map's readings over the union
    are made when asked, block by block, never the building's whole matrix (issue #66)."""

    bssids: np.ndarray
    cols: tuple[np.ndarray, ...]  # per map: where its (first of each) APs go in the union
    firsts: tuple[np.ndarray, ...]  # per map: its columns read (a repeated AP: the first)
    offsets: np.ndarray  # per map: its device offset (dB), removed from its readings
    aligned: bool  # whether offsets were fitted (else all 0)
    device: str  # the one phone model of every map, or ""

    @classmethod
    def of(cls, maps: Sequence[_Map], align_devices: bool) -> ApUnion:
        """The union of ``maps``' APs; ``align_devices``: each map's offset fitted on its
        rows not on standby (:mod:`.devices`) unless every map is of one phone model."""
        bssids = np.unique(np.concatenate([m.bssids for m in maps]))
        firsts = tuple(np.unique(m.bssids, return_index=True)[1] for m in maps)
        cols = tuple(np.searchsorted(bssids, m.bssids[f]) for m, f in zip(maps, firsts))
        off = np.zeros(len(maps))
        model = one_model(m.device for m in maps)
        align = align_devices and not model
        if align and len(maps) > 1:
            means = np.full((len(maps), bssids.size), np.nan)
            for i, (m, c, f) in enumerate(zip(maps, cols, firsts)):
                means[i, c] = ap_means(m.rss[~m.on_standby][:, f])
            off, _ = fit_offsets(means)
        return cls(bssids, cols, firsts, np.asarray(off, float), align, model)

    def readings(self, maps: Sequence[_Map], i: int, rows: np.ndarray) -> np.ndarray:
        """Map ``i``'s readings at its ``rows`` over the union (NaN: unheard), its offset
        removed."""
        out = np.full((rows.size, self.bssids.size), np.nan)
        out[:, self.cols[i]] = maps[i].rss[rows][:, self.firsts[i]] - self.offsets[i]
        return out

    def weakest(self, maps: Sequence[_Map]) -> float:
        """The weakest reading over the union (offsets removed; −100 when none was heard)."""
        low = [weakest(m.rss[:, f]) - o for m, f, o in zip(maps, self.firsts, self.offsets)
               if np.isfinite(m.rss[:, f]).any()]  # fmt: skip
        return min(low) if low else -100.0
