"""1-NN localization: queries per second in batch and the latency of one query, on
UJIIndoorLoc (19,937 reference points × 520 APs) when present and on the simulated office;
the radio map's index built once (``RadioMapIndex``), as a surveyor's session keeps it. Medians
of repeated runs with the interquartile range."""

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


def run() -> Table:
    tab = Table("1-NN localization")
    uji = SHARED_DATA / "ujiindoorloc" / "UJIIndoorLoc.zip"
    if uji.is_file():
        from workstation.fingerprints.uji import read_uji

        train, val = read_uji(uji)
        _figures(tab, "UJIIndoorLoc", train, val, align=False)
    rm = Fingerprints.from_session(simulate("office2f", "survey10", 1).session)
    q = Fingerprints.from_session(simulate("office2f", "heldout", 1).session)
    _figures(tab, "office survey map", rm, q, align=True)
    return tab


if __name__ == "__main__":
    run().print()
