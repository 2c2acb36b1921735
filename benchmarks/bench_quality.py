"""Radio-map quality maps: all heatmaps of one floor with 500 reference points and 100 APs
(bar: ≤ 1 s), on the simulated office's graph."""

from __future__ import annotations

import numpy as np
from _common import Table, median_of


def run() -> Table:
    from workstation.fingerprints.localize import Fingerprints
    from workstation.fingerprints.quality import floor_quality
    from workstation.sim.building import office2f

    g = office2f().graph
    rng = np.random.default_rng(0)
    pts = []
    for u, v in g.edges:
        a, b = g.node(u), g.node(v)
        if a.floor == b.floor == 0:
            s = rng.uniform(0, 1, 30)
            pts.append(np.column_stack([a.x + s * (b.x - a.x), a.y + s * (b.y - a.y)]))
    xy = np.vstack(pts)[:500]
    aps = rng.uniform([0, 0], [80, 50], (100, 2))
    d = np.hypot(xy[:, None, 0] - aps[None, :, 0], xy[:, None, 1] - aps[None, :, 1])
    rss = -40 - 25 * np.log10(1 + d) + rng.normal(0, 3, d.shape)
    rss[rss < -95] = np.nan
    fp = Fingerprints(
        xy[:, 0], xy[:, 1], np.zeros(len(xy)), np.array([f"ap{i}" for i in range(100)]), rss
    )
    med, iqr = median_of(lambda: floor_quality(fp, 0.0, g, n_aps=100), 5)
    t = Table(f"Quality maps: one floor, {len(xy)} reference points, 100 APs (bar ≤ 1 s)")
    t.add("all heatmaps + coverage + predicted error, median", 1e3 * med, "ms")
    t.add("interquartile range", 1e3 * iqr, "ms")
    return t


if __name__ == "__main__":
    run().print()
