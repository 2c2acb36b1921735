"""The search of :meth:`.reach.Reach._search`, compiled with Numba for large graphs (issue #18:
with the start inferred, every landmark of a 10,000-landmark graph is searched from). The same
lexicographic Dijkstra step by step — the same heap order (missed, length, push count), the
same sums in the same order — so the routes are identical; tests hold the two against each
other. Imported only for a graph of ``Reach.COMPILED_MIN`` landmarks or more (Numba takes a
third of a second to import)."""

from __future__ import annotations

import numba
import numpy as np

Arr = np.ndarray  # the kernel's arrays (numba types them when it compiles)


class Scratch:
    """Per-landmark work arrays, reused from one search to the next (a search marks what it
    touched with its own stamp instead of clearing them)."""

    def __init__(self, n: int):
        self.stamp = np.zeros(n, np.int64)  # == run: best/info valid in this search
        self.done = np.zeros(n, np.int64)  # == run: settled in this search
        self.best_m = np.zeros(n, np.int64)
        self.best_l = np.zeros(n)
        self.depth = np.zeros(n, np.int64)
        self.fc = np.zeros(n, np.bool_)
        self.climb = np.zeros(n)
        self.missed_at = np.zeros(n)
        self.run = 0
        self.heap_m = np.zeros(16, np.int64)  # the heap: missed, length, push count, landmark
        self.heap_l = np.zeros(16)
        self.heap_t = np.zeros(16, np.int64)
        self.heap_v = np.zeros(16, np.int64)

    def search(
        self, src: int, ptr: Arr, nbr: Arr, length: Arr, changes: Arr, heading: Arr,
        has_rules: Arr, max_hops: int, max_path: int,
    ) -> tuple:  # fmt: skip
        self.run += 1
        if self.heap_m.size < nbr.size + 1:  # a landmark is pushed at most once per edge
            size = nbr.size + 1
            self.heap_m, self.heap_t, self.heap_v = (np.zeros(size, np.int64) for _ in range(3))
            self.heap_l = np.zeros(size)
        return _search(src, self.run, ptr, nbr, length, changes, heading, has_rules, max_hops,
                       max_path, self.stamp, self.done, self.best_m, self.best_l, self.depth, self.fc, self.climb, self.missed_at, self.heap_m, self.heap_l,
                       self.heap_t, self.heap_v)  # fmt: skip


@numba.njit(inline="always", cache=True)
def _before(hm: Arr, hl: Arr, ht: Arr, i: int, j: int) -> bool:
    """Heap entry i comes before entry j: (missed, length, push count)."""
    if hm[i] != hm[j]:
        return hm[i] < hm[j]
    if hl[i] != hl[j]:
        return hl[i] < hl[j]
    return ht[i] < ht[j]


@numba.njit(inline="always", cache=True)
def _swap(hm: Arr, hl: Arr, ht: Arr, hv: Arr, i: int, j: int) -> None:
    hm[i], hm[j] = hm[j], hm[i]
    hl[i], hl[j] = hl[j], hl[i]
    ht[i], ht[j] = ht[j], ht[i]
    hv[i], hv[j] = hv[j], hv[i]


@numba.njit(inline="always", cache=True)
def _room(a: Arr, n: int) -> Arr:
    """``a``, doubled when its ``n`` entries fill it (room for one more)."""
    if n == a.size:
        return np.concatenate((a, np.empty_like(a)))
    return a


@numba.njit(inline="always", cache=True)
def _pop(hm: Arr, hl: Arr, ht: Arr, hv: Arr, size: int) -> None:
    """The heap's root taken: its last entry (at ``size``, the heap now that long) to the root,
    sifted down."""
    _swap(hm, hl, ht, hv, 0, size)
    i = 0
    while True:
        c = 2 * i + 1
        if c >= size:
            break
        if c + 1 < size and _before(hm, hl, ht, c + 1, c):
            c += 1
        if not _before(hm, hl, ht, c, i):
            break
        _swap(hm, hl, ht, hv, i, c)
        i = c


@numba.njit(inline="always", cache=True)
def _sift_up(hm: Arr, hl: Arr, ht: Arr, hv: Arr, i: int) -> None:
    """The entry just pushed at ``i`` sifted up to its place."""
    while i > 0 and _before(hm, hl, ht, i, (i - 1) // 2):
        _swap(hm, hl, ht, hv, i, (i - 1) // 2)
        i = (i - 1) // 2


@numba.njit(cache=True, nogil=True)
def _search(src: int, run: int, ptr: Arr, nbr: Arr, length: Arr, changes: Arr, heading: Arr,
            has_rules: Arr, max_hops: int, max_path: int, stamp: Arr, done: Arr, best_m: Arr,
            best_l: Arr, depth: Arr, fc: Arr, climb: Arr, missed_at: Arr, hm: Arr, hl: Arr,
            ht: Arr, hv: Arr) -> tuple:  # fmt: skip
    """Routes from ``src`` to the landmarks with rules, as arrays in :class:`.reach.Route`'s
    order (landmark, length, changes floor, edges, climb length, missed, length to the last
    missed), and the sorted distinct headings of the edges scanned (NaN in ``heading``: an
    edge not used for snapping)."""
    n_found = 0
    f_node = np.empty(16, np.int64)
    stamp[src] = run
    best_m[src] = 0
    best_l[src] = 0.0
    depth[src] = 1
    fc[src] = False
    climb[src] = 0.0
    missed_at[src] = 0.0
    heads = np.empty(16)
    n_heads = 0
    hm[0], hl[0], ht[0], hv[0] = 0, 0.0, 0, src
    size = 1
    tie = 0
    while size:
        length_u, u = hl[0], hv[0]
        size -= 1
        _pop(hm, hl, ht, hv, size)
        if done[u] == run:
            continue
        done[u] = run
        missed_before = best_m[u]
        ruled = u != src and has_rules[u]
        if ruled:
            f_node = _room(f_node, n_found)
            f_node[n_found] = u
            n_found += 1
        missed = missed_before + (1 if ruled else 0)
        if u != src and (fc[u] or missed >= max_hops):
            continue
        if depth[u] >= max_path:
            continue
        at = length_u if ruled else missed_at[u]
        for e in range(ptr[u], ptr[u + 1]):
            v = nbr[e]
            if done[v] == run:
                continue
            if not np.isnan(heading[e]):
                heads = _room(heads, n_heads)
                heads[n_heads] = heading[e]
                n_heads += 1
            lv = length_u + length[e]
            if stamp[v] == run and (
                best_m[v] < missed or (best_m[v] == missed and best_l[v] <= lv)
            ):
                continue
            stamp[v] = run
            best_m[v] = missed
            best_l[v] = lv
            depth[v] = depth[u] + 1
            fc[v] = fc[u] or changes[e]
            climb[v] = climb[u] + (length[e] if changes[e] else 0.0)
            missed_at[v] = at
            tie += 1
            hm[size], hl[size], ht[size], hv[size] = missed, lv, tie, v
            _sift_up(hm, hl, ht, hv, size)
            size += 1
    f_node = f_node[:n_found]
    # (missed, length), ties in the order found: a stable sort by length, then by missed
    order = np.argsort(best_l[f_node], kind="mergesort")
    order = order[np.argsort(best_m[f_node][order], kind="mergesort")]
    f_node = f_node[order]
    return (f_node, best_l[f_node], fc[f_node], depth[f_node] - 1, climb[f_node],
            best_m[f_node], missed_at[f_node], np.unique(heads[:n_heads]))  # fmt: skip
