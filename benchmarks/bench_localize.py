"""1-NN and the default matcher's localization: queries per second in batch and the latency of one query, on
UJIIndoorLoc (19,937 reference points × 520 APs) when present and on the simulated office;
the radio map's index built once (``RadioMapIndex``), as a surveyor's session keeps it. Medians
of repeated runs with the interquartile range. On UJIIndoorLoc, beside it in the same process
(issue #53): kNN (k = 4), and exact 1-NN by scikit-learn (brute force) and faiss (IndexFlatL2)
on the same positive fingerprints, with how many neighbours agree (``pip install -e .[bench]``
installs both; without them their lines say so)."""

from __future__ import annotations

import time

from _common import SHARED_DATA, Table, median_of

from workstation.fingerprints.localize import Fingerprints, Metric, RadioMapIndex
from workstation.sim import simulate


def _figures(tab: Table, name: str, rm: Fingerprints, q: Fingerprints, align: bool) -> None:
    import workstation.fingerprints.nn  # noqa: F401 - Numba's import is the process's, not the index's

    t = time.perf_counter()
    index = RadioMapIndex(rm)
    tab.add(f"{name}: index built once ({len(rm):,} RPs)", (time.perf_counter() - t) * 1e3, "ms")
    one = q.subset(slice(0, 1))
    for metric in Metric:
        index.localize(q, metric, align_device=align)  # warm: the kernel compiled or loaded
        sec, iqr = median_of(lambda m=metric: index.localize(q, m, align_device=align), 7)
        tab.add(f"{name} 1-NN {metric.value}, batch of {len(q):,}", len(q) / sec, "queries/s",
                "{:,.0f}")  # fmt: skip
        tab.add("   interquartile range", iqr / sec * len(q) / sec, "queries/s", "{:,.0f}")
        lat, _ = median_of(lambda m=metric: index.localize(one, m, align_device=align), 51)
        tab.add(f"{name} 1-NN {metric.value}, one query", lat * 1e3, "ms", "{:,.2f}")


def _default(tab: Table, name: str, rm: Fingerprints, q: Fingerprints, align: bool) -> None:
    """The default matcher (fingerprints/matchers.py, issue #63: ≥ 10,000 queries/s on
    UJIIndoorLoc): its index (powed values) built once, then batches."""
    from workstation.fingerprints.matchers import DEFAULT, METHODS

    m = METHODS[DEFAULT]
    index = RadioMapIndex(rm, representation=m.representation)
    run = lambda: index.localize(q, m.metric, m.k, align, m.weights)  # noqa: E731
    run()
    sec, iqr = median_of(run, 7)
    tab.add(f"{name} default matcher ({DEFAULT}), batch of {len(q):,}", len(q) / sec,
            "queries/s", "{:,.0f}")  # fmt: skip
    tab.add("   interquartile range", iqr / sec * len(q) / sec, "queries/s", "{:,.0f}")


def _others(tab: Table, index: RadioMapIndex, rm: Fingerprints, q: Fingerprints) -> None:
    """kNN, then scikit-learn's and faiss's exact 1-NN on the index's own fingerprints."""
    import numpy as np

    from workstation.fingerprints.localize import positive

    sec, _ = median_of(lambda: index.localize(q, Metric.EUCLIDEAN, k=4, align_device=False), 7)
    tab.add(f"UJIIndoorLoc kNN (k = 4) euclidean, batch of {len(q):,}", len(q) / sec,
            "queries/s", "{:,.0f}")  # fmt: skip
    ref = positive(rm.rss, index.tau, index.rss_min)
    qry = np.maximum(positive(q.aligned(rm.bssids), index.tau, index.rss_min), 0.0)
    ours = index.localize(q, Metric.EUCLIDEAN, align_device=False)
    want = np.asarray(ours.index)
    d_ours = np.sqrt(((qry - ref[want]) ** 2).sum(axis=1))

    def agree(name: str, got: np.ndarray) -> None:
        same = int((got == want).sum())
        d_got = np.sqrt(((qry - ref[got]) ** 2).sum(axis=1))
        ties = int(((got != want) & np.isclose(d_got, d_ours, rtol=0, atol=1e-6)).sum())
        tab.add(f"   {name}: neighbour as ours / at the same distance (a tie)", same, "queries",
                "{:,.0f}" + f" / {ties}")  # fmt: skip

    try:
        from sklearn.neighbors import NearestNeighbors
    except ImportError:
        tab.add("scikit-learn 1-NN brute: not installed (pip install -e .[bench])", 0, "")
    else:
        nn = NearestNeighbors(n_neighbors=1, algorithm="brute").fit(ref)
        sec, _ = median_of(lambda: nn.kneighbors(qry), 5)
        tab.add("scikit-learn 1-NN brute force, same process", len(q) / sec, "queries/s",
                "{:,.0f}")  # fmt: skip
        agree("scikit-learn", nn.kneighbors(qry)[1][:, 0])
    try:
        import faiss
    except ImportError:
        tab.add("faiss IndexFlatL2: not installed (pip install -e .[bench])", 0, "")
    else:
        flat = faiss.IndexFlatL2(ref.shape[1])
        flat.add(np.ascontiguousarray(ref, np.float32))
        q32 = np.ascontiguousarray(qry, np.float32)
        sec, _ = median_of(lambda: flat.search(q32, 1), 5)
        tab.add("faiss IndexFlatL2 1-NN, same process", len(q) / sec, "queries/s", "{:,.0f}")
        agree("faiss", flat.search(q32, 1)[1][:, 0])


def run() -> Table:
    tab = Table("1-NN localization")
    uji = SHARED_DATA / "ujiindoorloc" / "UJIIndoorLoc.zip"
    if uji.is_file():
        from workstation.fingerprints.uji import read_uji

        train, val = read_uji(uji)
        _figures(tab, "UJIIndoorLoc", train, val, align=False)
        _default(tab, "UJIIndoorLoc", train, val, align=False)
        _others(tab, RadioMapIndex(train), train, val)
    rm = Fingerprints.from_session(simulate("office2f", "survey10", 1).session)
    q = Fingerprints.from_session(simulate("office2f", "heldout", 1).session)
    _figures(tab, "office survey map", rm, q, align=True)
    _default(tab, "office survey map", rm, q, align=True)
    return tab


if __name__ == "__main__":
    run().print()
