"""The client's memory in the multi-walk steps (issue #66): a building's walks over thousands of
access points make a dense merged matrix of rows × APs, 0.8 GB a copy at the 10,000-walk
campaign's 40,000 rows; eq. 21 used to make four of it at once. Counted with tracemalloc (the
bytes allocated, not the machine's load): the joint estimate never holds that matrix, the merge
holds it once, the leave-one-out little more — and their results are those of the dense code."""

from __future__ import annotations

import tracemalloc

import numpy as np

from workstation.fingerprints.leave_out import leave_one_walk_out
from workstation.fingerprints.localize import Fingerprints, positive
from workstation.fingerprints.matchers import DEFAULT, METHODS
from workstation.fingerprints.nn import InvertedIndex
from workstation.walks.joint import correct

WALKS, ROWS, APS, HEARD = 60, 30, 3000, 25


def _maps(seed: int) -> dict[str, Fingerprints]:
    """Walks along a 300-m mall, each hearing the ~25 of 3,000 APs near it."""
    rng = np.random.default_rng(seed)
    out = {}
    for w in range(WALKS):
        x = np.sort(rng.uniform(0, 300, ROWS))
        ap = np.unique(np.clip((x[:, None] / 0.1 + rng.integers(-40, 40, (ROWS, HEARD))), 0,
                               APS - 1).astype(int))  # fmt: skip
        rss = -50 - 0.5 * np.abs(ap[None, :] * 0.1 - x[:, None]) + rng.normal(0, 3, (ROWS, ap.size))
        rss[rng.random(rss.shape) < 0.5] = np.nan
        out[f"w{w}"] = Fingerprints(x + rng.normal(0, 1, ROWS), rng.normal(0, 1, ROWS),
                                    np.zeros(ROWS), np.array([f"ap{a:04d}" for a in ap]),
                                    np.round(rss), t=np.arange(ROWS) * 2.0,
                                    sigma=np.full(ROWS, 1.5), device=f"phone{w % 3}")  # fmt: skip
    return out


def _peak(fn):
    tracemalloc.start()
    try:
        out = fn()
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_the_multi_walk_steps_never_copy_the_building_matrix_whole():
    maps = _maps(1)
    few = {k: maps[k] for k in list(maps)[:3]}
    correct(few, -90.0, True), leave_one_walk_out(few, few, METHODS[DEFAULT])  # imports, compiles
    dense = WALKS * ROWS * len(np.unique(np.concatenate([m.bssids for m in maps.values()]))) * 8
    _, joint = _peak(lambda: correct(maps, -90.0, True))
    assert joint < 0.5 * dense  # the links' index from each walk's block, never the floor's matrix
    merged, merging = _peak(lambda: Fingerprints.merge(list(maps.values()), align_devices=True))
    assert merged.rss.nbytes == dense and merging < 1.5 * dense  # the result, and little else
    _, loo = _peak(lambda: leave_one_walk_out(maps, maps, METHODS[DEFAULT]))
    assert loo < 2.0 * dense


def test_the_index_built_block_by_block_is_the_index_built_whole():
    maps = _maps(2)
    merged = Fingerprints.merge(list(maps.values()), align_devices=True)
    pos = np.maximum(positive(merged.rss, -90.0, np.nanmin(merged.rss) - 1), 0.0)
    whole = InvertedIndex.build(pos)
    blocks = InvertedIndex.from_blocks(pos[i : i + 97] for i in range(0, len(pos), 97))
    for f in ("n", "col_ptr", "col_row", "col_val", "sq", "total", "by_sq", "by_total"):
        assert np.array_equal(getattr(whole, f), getattr(blocks, f)), f
    q = pos[::7]
    for metric in ("euclidean", "sorensen"):
        a, b = whole.search(q, metric, 3), blocks.search(q, metric, 3)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_the_campaign_s_map_table_is_the_frame_s_without_the_frame():
    """The building's map written column by column from its arrays (export.fingerprints_table)
    holds what the pandas frame's table held: the same columns, types, values and nulls."""
    from workstation.export import fingerprints_table, map_table

    m = Fingerprints.merge(list(_maps(3).values()), align_devices=True, settle=False)
    df = m.to_frame()
    df.columns = [str(c) for c in df.columns]
    df.insert(0, "building", "mall")
    a, b = map_table(df, m.frame, m.device, m.kind), fingerprints_table(m, "mall")
    assert a.column_names == b.column_names and a.schema.types == b.schema.types
    assert a.equals(b)  # values and nulls, column by column
    key = b"workstation"
    assert a.schema.metadata[key] == b.schema.metadata[key]
