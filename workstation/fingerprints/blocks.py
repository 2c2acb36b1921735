"""A map's RSS matrix a block of rows at a time (issue #66): what is made of each block — eq. 21's
positive values, an index's values, per-AP sums — then never exists for the whole map at once.
A building's merged map is 0.8 GB a copy at 40,000 rows × 2,400 APs; eq. 21 made four."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

#: the bytes of a block of rows (float64)
BLOCK_BYTES = 1 << 22


def row_blocks(rss: np.ndarray, rows: np.ndarray | None = None) -> Iterator[np.ndarray]:
    """``rss`` (or its ``rows``, in their order) ``BLOCK_BYTES`` at a time."""
    n = rss.shape[0] if rows is None else rows.size
    step = max(64, BLOCK_BYTES // (8 * max(rss.shape[1] if rss.ndim == 2 else 1, 1)))
    for i in range(0, n, step):
        yield rss[i : i + step] if rows is None else rss[rows[i : i + step]]


def weakest(rss: np.ndarray) -> float:
    """A map's weakest reading (dBm; −100 when it heard nothing)."""
    low = [float(b[np.isfinite(b)].min()) for b in row_blocks(rss) if np.isfinite(b).any()]
    return min(low) if low else -100.0
