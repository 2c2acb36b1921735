"""Device RSS offsets: phones of different makes read the same AP at the same spot several dB
apart (on the museum walks the Samsung A5 reads 6–7 dB above the S7), which 1-NN on raw RSS
mistakes for distance. Beyond the paper; docs/decisions.md, "Device RSS offsets".

Model: the mean RSS of AP ``a`` over the scans of walk ``w`` that heard it is
``m[w, a] = μ[a] + o[w] + e`` — an AP level shared by all walks plus one offset per walk
(device). The offsets are fitted by median polish (Tukey), robust to APs whose level differs
between walks because the walks covered different parts of the building, and centred so that
their median is 0. A query walk's offset against a map is ``median_a(m[q, a] − μ[a])`` over the
APs both heard; the query is shifted by −offset before 1-NN. Estimates need ``MIN_SHARED_APS``
APs in common, each heard in ``MIN_SCANS`` scans; otherwise the offset is 0.
"""

from __future__ import annotations

import numpy as np

from workstation.fingerprints.blocks import row_blocks

MIN_SHARED_APS = 5
MIN_SCANS = 2


def one_model(models) -> str:
    """The phone model every walk was recorded with, or "" when they differ or one is unknown.
    Offsets are a property of the model: walks of one model have nothing to align (on the
    mall's one-model walks the per-walk offsets fitted ±8 dB of coverage differences, not
    phones, and cost the tap-oracle map 0.7 m: docs/decisions.md)."""
    models = {m or "" for m in models}
    return models.pop() if len(models) == 1 else ""


def ap_means(rss: np.ndarray) -> np.ndarray:
    """Per AP (column): mean RSS over the scans that heard it; NaN if heard fewer than
    ``MIN_SCANS`` times."""
    rss = np.asarray(rss, float)
    n = np.zeros(rss.shape[1] if rss.ndim == 2 else 0)
    s = np.zeros_like(n)
    for b in row_blocks(rss):  # a building's map is never copied whole (blocks.py)
        heard = np.isfinite(b)
        n += heard.sum(axis=0)
        s += np.where(heard, b, 0.0).sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n >= MIN_SCANS, s / n, np.nan)


def offset_against(levels: np.ndarray, means: np.ndarray) -> float:
    """The offset of one walk (its per-AP ``means``) against AP ``levels`` (dB; 0 if too few
    APs in common)."""
    d = np.asarray(means, float) - np.asarray(levels, float)
    d = d[np.isfinite(d)]
    return float(np.median(d)) if d.size >= MIN_SHARED_APS else 0.0


def fit_offsets(means: np.ndarray, iterations: int = 10) -> tuple[np.ndarray, np.ndarray]:
    """Median polish of ``means`` (walks × APs, NaN where unheard): (offset per walk, level per
    AP). Offsets are centred on their median; walks sharing too few APs get 0."""
    m = np.asarray(means, float)
    off = np.zeros(m.shape[0])
    lev = np.full(m.shape[1], np.nan)
    if m.size == 0:
        return off, lev
    for _ in range(iterations):
        with np.errstate(all="ignore"):
            lev = _nanmedian(m - off[:, None], axis=0)
        new = np.array([offset_against(lev, row) for row in m])
        new -= np.median(new)
        done = np.allclose(new, off, atol=0.01)
        off = new
        if done:
            break
    with np.errstate(all="ignore"):
        lev = _nanmedian(m - off[:, None], axis=0)
    return off, lev


def _nanmedian(a: np.ndarray, axis: int) -> np.ndarray:
    """np.nanmedian without the all-NaN warning (columns no walk heard stay NaN)."""
    ok = np.isfinite(a).any(axis=axis)
    out = np.full(a.shape[1 - axis], np.nan)
    if ok.any():
        sub = a[:, ok] if axis == 0 else a[ok]
        out[ok] = np.nanmedian(sub, axis=axis)
    return out
