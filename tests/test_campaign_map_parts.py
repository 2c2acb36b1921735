"""A building's merged map written a block of rows at a time (issue #66: an Arrow table of the
whole map and the copies partitioning made of it held the client of a 10,000-walk campaign at
3.2 GB): read back, it is the map — every row in order, every floor, its metadata."""

from __future__ import annotations

import numpy as np
import pytest

from workstation.campaign import report
from workstation.fingerprints.localize import Fingerprints
from workstation.io.map_read import read_map


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_map_written_in_blocks_reads_back_as_it_was(tmp_path, monkeypatch, seed):
    rng = np.random.default_rng(seed)
    n, a = 257, 9
    rss = np.where(rng.random((n, a)) < 0.4, rng.uniform(-95, -40, (n, a)).round(1), np.nan)
    fp = Fingerprints(rng.uniform(0, 50, n), rng.uniform(0, 30, n),
                      rng.choice([-1.0, 0.0, 2.0], n), np.array([f"ap{i}" for i in range(a)]),
                      rss, device="pixel", sigma=rng.uniform(0.5, 4, n).round(3))  # fmt: skip
    monkeypatch.setattr(report, "BLOCK_BYTES", 8 * a * 40)  # 40 rows a block: 7 blocks
    report._write_dataset(fp, tmp_path, "mall")
    parts = sorted((tmp_path / "radiomap" / "building=mall").glob("floor=*/*.parquet"))
    assert len(parts) == 7 * 3
    back = read_map(tmp_path / "radiomap" / "building=mall")
    for f in (-1.0, 0.0, 2.0):  # within a floor, the rows in the map's order
        mine, theirs = fp.floor == f, back["floor"] == f
        assert np.array_equal(back["x"][theirs], fp.x[mine])
        assert np.array_equal(back["sigma"][theirs], fp.sigma[mine])
        cols = [list(back["bssids"]).index(b) for b in fp.bssids]
        assert np.array_equal(back["rss"][theirs][:, cols], fp.rss[mine], equal_nan=True)
    assert back["device"] == "pixel"
    # written again: the parts before are gone, not mixed in
    report._write_dataset(fp.subset(slice(0, 10)), tmp_path, "mall")
    assert len(read_map(tmp_path / "radiomap" / "building=mall")["x"]) == 10
