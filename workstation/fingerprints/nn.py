"""Nearest fingerprints (§V-C) over an inverted index: the exact k nearest reference points by
Euclidean or Sørensen distance, touching only the reference points that share an access point
with the query (issue #17).

Fingerprints are in the positive representation (eq. 21): 0 where an AP is unheard. A query
hears ~15 of hundreds of APs, so the work that matters is sparse:

- Euclidean: d² = |q|² + |r|² − 2 q·r, and q·r = Σ over the query's APs of q_a r_a;
- Sørensen (Bray–Curtis): d = (Σq + Σr − 2 Σ min(q_a, r_a)) / (Σq + Σr).

For each query AP the index lists the reference points that hear it (a CSC matrix), so the
products and minima are accumulated only over those. Reference points sharing no AP with the
query have q·r = 0 and Σmin = 0: their distance depends on the reference point alone, so they
are visited in the order of that distance (precomputed) and only while they could still enter
the k best. When a query's lists hold about as many entries as the map has points (UJIIndoorLoc:
20,000 of 19,937) the bookkeeping of touched points costs more than the products: such a query
accumulates blindly and then takes one pass over every point. Ties go to the lower index.

Phones report RSS in whole dBm, so the positive values are usually small integers: then the
index stores them as bytes and a query whose values are whole too accumulates in int32 — the
same sums exactly (they are integers far below 2^31), in half the memory traffic; UJIIndoorLoc
1-NN runs 1.5× faster. Any fractional value (a device offset, an averaged map) takes the
float64 path. The kernel is compiled with Numba, one query per thread; the index is built once
per radio map and kept (:class:`~.localize.RadioMapIndex`).
Import this module only where a search runs: Numba takes a third of a second to import.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numba
import numpy as np

from workstation.errors import WorkstationError

# a query whose AP lists hold at least 1/DENSE_RATIO as many entries as the map has points is
# searched by one pass over every point (no bookkeeping of the touched ones): UJIIndoorLoc's
# queries touch 20,000 list entries of a 19,937-point map
DENSE_RATIO = 4
# whole-dB fingerprints are stored as bytes; a product is below 255² and a query's sum of them
# must stay below 2^31 in the int32 accumulator
WHOLE_MAX = 255


def _whole(values: np.ndarray) -> bool:
    """Values that are integers in [0, WHOLE_MAX] (the byte path is exact for them)."""
    return bool(((values <= WHOLE_MAX) & (values == np.round(values))).all())


@dataclass(frozen=True)
class InvertedIndex:
    """Reference fingerprints (N × A, positive representation) by access point."""

    n: int
    col_ptr: np.ndarray  # (A + 1,) start of each AP's list
    col_row: np.ndarray  # reference points that hear the AP (uint16 when they fit)
    col_val: np.ndarray  # their values (uint8 when all are whole, else float64)
    sq: np.ndarray  # |r|² per reference point
    total: np.ndarray  # Σ r per reference point
    by_sq: np.ndarray  # reference points by |r|², then index (Euclidean, nothing shared)
    by_total: np.ndarray  # empty ones first, then by index (Sørensen, nothing shared)

    @classmethod
    def build(cls, ref: np.ndarray) -> InvertedIndex:
        return cls.from_blocks([ref])

    @classmethod
    def from_blocks(cls, blocks: Iterable[np.ndarray]) -> InvertedIndex:
        """The index of the reference points given as consecutive blocks of rows (dense, each
        small): a building's map is never dense in one piece here — 40,000 points × 2,400
        APs is 0.8 GB a copy, and eq. 21 made four (issue #66)."""
        rows: list[np.ndarray] = []
        cols: list[np.ndarray] = []
        vals: list[np.ndarray] = []
        sqs: list[np.ndarray] = []
        totals: list[np.ndarray] = []
        n, width = 0, None
        for ref in blocks:
            ref = np.asarray(ref, dtype=np.float64)
            if ref.ndim != 2 or not np.isfinite(ref).all() or (ref < 0).any():
                raise WorkstationError("fingerprints must be a finite, non-negative matrix")
            if width is not None and ref.shape[1] != width:
                raise WorkstationError("fingerprint blocks over different access points")
            width = ref.shape[1]
            r, c = np.nonzero(ref)  # by reference point, then AP
            vals.append(ref[r, c])
            rows.append((r + n).astype(np.int32))
            cols.append(c.astype(np.int32))
            sqs.append(np.einsum("ij,ij->i", ref, ref))
            totals.append(ref.sum(axis=1))
            n += ref.shape[0]
        if width is None:
            raise WorkstationError("fingerprints must be a finite, non-negative matrix")
        col = np.concatenate(cols)
        cols.clear()
        ptr = np.zeros(width + 1, np.int64)
        np.cumsum(np.bincount(col, minlength=width), out=ptr[1:])
        by_ap = np.argsort(col, kind="stable")  # by AP, then (as they came) reference point
        del col
        row = np.concatenate(rows)
        rows.clear()
        row = row[by_ap]
        val = np.concatenate(vals)
        vals.clear()
        val = val[by_ap]
        sq, total = np.concatenate(sqs), np.concatenate(totals)
        return cls(
            n,
            ptr,
            row.astype(np.uint16 if n <= 65536 else np.int32),  # half the bytes
            val.astype(np.uint8) if _whole(val) else val,
            sq,
            total,
            np.argsort(sq, kind="stable"),
            np.argsort(total > 0, kind="stable"),
        )

    def search_without(
        self, qry: np.ndarray, k: int, lo: int, hi: int, metric: str = "euclidean"
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`search` as if the reference points ``lo:hi`` were not there: their |r|² is
        infinite, so no query comes nearer to them than to any other point (Sørensen: an
        infinite |r|² marks a point out, :func:`_distance`), and the order of the points
        sharing nothing is taken again (the leave-one-walk-out of ``evaluate --walks``: one
        index for every walk's map of one kind). Indices are into the whole index."""
        if hi - lo >= self.n:
            raise WorkstationError("no reference point is left")
        sq = self.sq.copy()
        sq[lo:hi] = np.inf
        if metric == "sorensen":  # the points out last, then as by_total
            order = np.lexsort((np.arange(self.n), self.total > 0, ~np.isfinite(sq)))
        else:
            order = np.argsort(sq, kind="stable")
        return self.search(qry, metric, min(k, self.n - (hi - lo)), sq=sq, order=order)

    def search(
        self, qry: np.ndarray, metric: str, k: int, sq=None, order=None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Indices (Q, k) and distances (Q, k) of the k nearest reference points, nearest first
        (``sq``, ``order``: :meth:`search_without`'s)."""
        qry = np.asarray(qry, dtype=np.float64)
        if qry.ndim != 2 or qry.shape[1] != self.col_ptr.size - 1:
            raise WorkstationError("queries must be a matrix over the index's access points")
        k = min(k, self.n)
        rows, cols = np.nonzero(qry)
        ptr = np.zeros(qry.shape[0] + 1, np.int64)
        np.cumsum(np.bincount(rows, minlength=qry.shape[0]), out=ptr[1:])
        out_i = np.empty((qry.shape[0], k), np.int64)
        out_d = np.empty((qry.shape[0], k))
        if k == 0 or not qry.shape[0]:
            return out_i, out_d
        sorensen = metric == "sorensen"
        vals = qry[rows, cols]
        if self.col_val.dtype == np.uint8 and qry.shape[1] * WHOLE_MAX**2 < 2**31 and _whole(vals):
            vals = vals.astype(np.int32)  # accumulated in int32: exact, half the traffic
        if order is None:
            order = self.by_total if sorensen else self.by_sq
        _search(ptr, cols.astype(np.int64), vals, self.col_ptr, self.col_row,
               self.col_val, self.sq if sq is None else sq, self.total, order,
               sorensen, out_i, out_d)  # fmt: skip
        return out_i, out_d


@numba.njit(inline="always", cache=True)
def _insert(bi, bd, m, r, d):
    """Insert (d, r) into the sorted top list holding m ≤ k entries (ties by index); the new m."""
    k = bi.size
    if m == k and (d > bd[k - 1] or (d == bd[k - 1] and r > bi[k - 1])):
        return m
    j = m if m < k else k - 1
    while j > 0 and (bd[j - 1] > d or (bd[j - 1] == d and bi[j - 1] > r)):
        bd[j] = bd[j - 1]
        bi[j] = bi[j - 1]
        j -= 1
    bd[j] = d
    bi[j] = r
    return m + 1 if m < k else m


@numba.njit(inline="always", cache=True)
def _sums(i, q_ptr, q_val):
    """Σ q and Σ q² of query i."""
    qs = 0.0
    qq = 0.0
    for p in range(q_ptr[i], q_ptr[i + 1]):
        qs += q_val[p]
        qq += q_val[p] * q_val[p]
    return qs, qq


@numba.njit(inline="always", cache=True)
def _distance(sorensen, qs, qq, total_r, sq_r, s):
    """Sørensen or squared Euclidean distance from the query's sums, the point's and the shared
    sum ``s`` (Σ min or Σ products over the shared APs; 0 when nothing is shared)."""
    if sorensen:
        if sq_r == np.inf:  # a point left out (search_without)
            return np.inf
        tot = qs + total_r
        return (tot - 2.0 * s) / tot if tot > 0 else 0.0
    return qq + sq_r - 2.0 * s


@numba.njit(cache=True, nogil=True)
def _one(i, q_ptr, q_col, q_val, c_ptr, c_row, c_val, sq, total, order, sorensen, acc, touched,
         bi, bd):  # fmt: skip
    """The k nearest to query i into (bi, bd); ``acc`` is all zero before and after."""
    k = bi.size
    n = sq.size
    work = 0
    for p in range(q_ptr[i], q_ptr[i + 1]):
        work += c_ptr[q_col[p] + 1] - c_ptr[q_col[p]]
    if n <= DENSE_RATIO * work:
        _one_dense(i, q_ptr, q_col, q_val, c_ptr, c_row, c_val, sq, total, sorensen, acc, bi, bd)
        return
    nt = 0
    qs, qq = _sums(i, q_ptr, q_val)
    for p in range(q_ptr[i], q_ptr[i + 1]):  # accumulate over the lists of the query's APs
        a = q_col[p]
        v = q_val[p]
        if sorensen:
            for c in range(c_ptr[a], c_ptr[a + 1]):
                r = c_row[c]
                if acc[r] == 0.0:  # > 0 exactly where an AP is shared (all values are > 0)
                    touched[nt] = r
                    nt += 1
                acc[r] += min(v, c_val[c])
        else:
            for c in range(c_ptr[a], c_ptr[a + 1]):
                r = c_row[c]
                if acc[r] == 0.0:
                    touched[nt] = r
                    nt += 1
                acc[r] += v * c_val[c]
    m = 0  # entries in the running top k
    for t in range(nt):
        r = touched[t]
        d = _distance(sorensen, qs, qq, total[r], sq[r], acc[r])
        if m < k or d < bd[k - 1] or (d == bd[k - 1] and r < bi[k - 1]):
            m = _insert(bi, bd, m, r, d)
    for t in range(order.size):  # nothing shared: by that distance, while it can still enter
        r = order[t]
        if acc[r] > 0.0:
            continue
        d = _distance(sorensen, qs, qq, total[r], sq[r], 0.0)
        if m == k and d > bd[k - 1]:
            break
        m = _insert(bi, bd, m, r, d)
    for t in range(nt):
        acc[touched[t]] = 0.0


@numba.njit(cache=True, nogil=True)
def _one_dense(i, q_ptr, q_col, q_val, c_ptr, c_row, c_val, sq, total, sorensen, acc, bi, bd):
    """:func:`_one` when the query's lists hold about as many entries as the map has points:
    accumulate without keeping track of who was touched, then one pass over every reference
    point (a point sharing nothing has acc 0, which gives its distance exactly). The branch
    that tracked the touched points cost more than the products themselves."""
    k = bi.size
    qs, qq = _sums(i, q_ptr, q_val)
    for p in range(q_ptr[i], q_ptr[i + 1]):
        a = q_col[p]
        v = q_val[p]
        if sorensen:
            for c in range(c_ptr[a], c_ptr[a + 1]):
                acc[c_row[c]] += min(v, c_val[c])
        else:
            for c in range(c_ptr[a], c_ptr[a + 1]):
                acc[c_row[c]] += v * c_val[c]
    if k == 1:  # 1-NN, the common case: a plain running minimum
        best = np.inf
        b = 0
        if sorensen:
            for r in range(sq.size):
                d = _distance(True, qs, qq, total[r], sq[r], acc[r])
                acc[r] = 0
                if d < best:  # ascending index: a tie keeps the earlier point
                    best = d
                    b = r
        else:
            for r in range(sq.size):
                d = qq + sq[r] - 2.0 * acc[r]
                acc[r] = 0
                if d < best:
                    best = d
                    b = r
        bi[0] = b
        bd[0] = best
        return
    m = 0
    for r in range(sq.size):  # ascending index: a tie never displaces an earlier point
        s = acc[r]
        acc[r] = 0  # ready for the next query
        d = _distance(sorensen, qs, qq, total[r], sq[r], s)
        if m < k or d < bd[k - 1]:
            m = _insert(bi, bd, m, r, d)


@numba.njit(parallel=True, cache=True, nogil=True)
def _search(q_ptr, q_col, q_val, c_ptr, c_row, c_val, sq, total, order, sorensen, out_i, out_d):
    nq = q_ptr.size - 1
    n = sq.size
    k = out_i.shape[1]
    chunks = min(nq, 64)
    size = (nq + chunks - 1) // chunks
    for ch in numba.prange(chunks):  # one accumulator per chunk of queries
        acc = np.zeros(n, q_val.dtype)  # int32 for whole-dB queries
        touched = np.empty(n, np.int32)
        bi = np.empty(k, np.int64)
        bd = np.empty(k)
        for i in range(ch * size, min(nq, (ch + 1) * size)):
            _one(i, q_ptr, q_col, q_val, c_ptr, c_row, c_val, sq, total, order, sorensen, acc,
                 touched, bi, bd)  # fmt: skip
            for j in range(k):
                out_i[i, j] = bi[j]
                out_d[i, j] = bd[j] if sorensen else np.sqrt(max(bd[j], 0.0))
