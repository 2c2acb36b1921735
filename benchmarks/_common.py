"""Benchmark helpers: best-of-N timing and a figure table. Speed lives here, not in unit tests."""

from __future__ import annotations

import os
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("WORKSTATION_SHARED_DATA", REPO.parent / "shared" / "data"))


def median_of(fn, repeat: int = 5) -> tuple[float, float]:
    """(median, interquartile range) of the wall times of ``repeat`` calls, seconds."""
    import statistics

    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    q = statistics.quantiles(ts, n=4) if len(ts) > 1 else [ts[0]] * 3
    return statistics.median(ts), q[2] - q[0]


def best_of(fn, repeat: int = 5) -> float:
    """Best wall time of ``repeat`` calls, seconds."""
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


class Table:
    def __init__(self, title: str):
        self.title = title
        self.rows: list[tuple[str, str, str]] = []

    def add(self, what: str, value: float, unit: str, fmt: str = "{:,.1f}") -> None:
        self.rows.append((what, fmt.format(value), unit))

    def to_dict(self) -> dict:
        return {"title": self.title,
                "rows": [{"what": w.strip(), "value": v, "unit": u} for w, v, u in self.rows]}  # fmt: skip

    def print(self) -> None:
        print(f"\n## {self.title}")
        w = max((len(r[0]) for r in self.rows), default=10)
        for what, v, unit in self.rows:
            print(f"  {what:<{w}}  {v:>12}  {unit}")
