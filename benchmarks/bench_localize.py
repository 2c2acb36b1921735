"""1-NN queries per second: UJIIndoorLoc (19,937 reference points × 520 APs) when present,
and the simulated office."""

from __future__ import annotations

from _common import SHARED_DATA, Table, best_of

from workstation.localize import Fingerprints, Metric, localize
from workstation.sim import simulate


def run() -> Table:
    tab = Table("1-NN localization")
    uji = SHARED_DATA / "ujiindoorloc" / "UJIIndoorLoc.zip"
    if uji.is_file():
        from workstation.uji import read_uji

        train, val = read_uji(uji)
        for metric in Metric:
            sec = best_of(lambda m=metric: localize(train, val, m, k=1, align_device=False), 2)
            tab.add(
                f"UJIIndoorLoc 1-NN {metric.value} ({len(train):,} RPs)",
                len(val) / sec,
                "queries/s",
                "{:,.0f}",
            )
    rm = Fingerprints.from_session(simulate("office2f", "survey10", 1).session)
    q = Fingerprints.from_session(simulate("office2f", "heldout", 1).session)
    for metric in Metric:
        sec = best_of(lambda m=metric: localize(rm, q, m, k=1), 5)
        tab.add(
            f"office survey map 1-NN {metric.value} ({len(rm):,} RPs)",
            len(q) / sec,
            "queries/s",
            "{:,.0f}",
        )
    return tab
