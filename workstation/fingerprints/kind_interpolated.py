"""The ``interpolated`` radio map: virtual reference points every ``STEP_M`` over the space the
walks covered, each AP's reading there a σ-weighted kernel average of the walks' scans near it
(issue #63; Nadaraya–Watson regression, the mean a Gaussian process converges to with dense
data and a short kernel — without its N³ solve).

For a virtual point g and the map's points j on its floor within ``REACH`` · ``LENGTH_M``:

    w_gj = exp(−d_gj² / 2ℓ²) / (σ_j² + ``SIGMA_FLOOR_M``²)

(ℓ = ``LENGTH_M``; σ_j the point's placement σ — a loosely placed scan counts less). Per AP,
heard share h = Σ_j w_gj [j heard it] / Σ_j w_gj; g hears it when h ≥ ½, at the weighted mean
of the readings that heard it (dBm). Its σ: the weighted RMS of the σ_j, with the distance to
the nearest point added in quadrature. The grid keeps the cells within ``NEAR_M`` of a point
on the floor: the walkable space as the walks walked it (no point is made through a wall no
walk crossed, beyond ``NEAR_M``).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from workstation.fingerprints.kinds import MapKind

if TYPE_CHECKING:
    from workstation.fingerprints.localize import Fingerprints

STEP_M = 1.5  # spacing of the virtual reference points
NEAR_M = 2.0  # a virtual point lies within this of one of the walks' points
LENGTH_M = 2.0  # the kernel's length ℓ
REACH = 3.0  # points farther than REACH · ℓ weigh nothing
SIGMA_FLOOR_M = 1.0  # added to σ_j in quadrature: no point weighs infinitely


def _grid(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The cells every ``STEP_M`` within ``NEAR_M`` of a point (x, y)."""
    from scipy.spatial import cKDTree

    gx = np.arange(x.min() - NEAR_M, x.max() + NEAR_M + STEP_M, STEP_M)
    gy = np.arange(y.min() - NEAR_M, y.max() + NEAR_M + STEP_M, STEP_M)
    g = np.column_stack([a.ravel() for a in np.meshgrid(gx, gy)])
    d, _ = cKDTree(np.column_stack([x, y])).query(g, distance_upper_bound=NEAR_M)
    return g[np.isfinite(d)]


def _floor(m: Fingerprints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One floor's virtual points: positions (G, 2), readings (G, A) dBm, σ (G,)."""
    from scipy import sparse
    from scipy.spatial import cKDTree

    g = _grid(m.x, m.y)
    pts = cKDTree(np.column_stack([m.x, m.y]))
    d = cKDTree(g).sparse_distance_matrix(pts, REACH * LENGTH_M, output_type="coo_matrix")
    sig = m.sigma if m.sigma is not None else np.zeros(len(m))
    sig = np.where(np.isfinite(sig), sig, 10 * LENGTH_M)
    w = np.exp(-(d.data**2) / (2 * LENGTH_M**2)) / (sig[d.col] ** 2 + SIGMA_FLOOR_M**2)
    # (a point on a cell has distance 0, which the sparse matrix drops: added back)
    near_d, near_j = pts.query(g)
    on = near_d == 0
    W = sparse.coo_matrix((np.concatenate([w, 1 / (sig[near_j[on]] ** 2 + SIGMA_FLOOR_M**2)]),
                           (np.concatenate([d.row, np.flatnonzero(on)]),
                            np.concatenate([d.col, near_j[on]]))),
                          shape=(len(g), len(m))).tocsr()  # fmt: skip
    heard = np.isfinite(m.rss)
    total = np.asarray(W.sum(axis=1)).ravel()
    h = W @ heard.astype(float)
    level = W @ np.where(heard, m.rss, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        rss = np.where(h >= 0.5 * total[:, None], level / h, np.nan)
        spread = np.sqrt((W @ sig**2) / total)
    keep = total > 0
    return g[keep], rss[keep], np.hypot(spread, near_d)[keep]


def build(merged: Fingerprints, graph: Any = None) -> Fingerprints:
    """Virtual reference points over every floor of ``merged`` (module docstring)."""
    parts = [_floor(merged.subset(merged.floor == f)) for f in np.unique(merged.floor)]
    floors = np.concatenate([np.full(len(p[0]), f) for p, f in zip(parts, np.unique(merged.floor))])
    xy = np.vstack([p[0] for p in parts])
    return replace(merged, x=xy[:, 0], y=xy[:, 1], floor=floors,
                   rss=np.vstack([p[1] for p in parts]), sigma=np.concatenate([p[2] for p in parts]),
                   t=None, standby=None)  # fmt: skip


KIND = MapKind("interpolated", f"virtual points every {STEP_M:g} m where the walks went, each "
               "AP's reading a σ-weighted kernel average of the scans near it", build)  # fmt: skip
