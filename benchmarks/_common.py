"""Benchmark helpers: best-of-N timing and a figure table. Speed lives here, not in unit tests."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
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


@contextmanager
def with_bar(t: Table, what: str, value: float, unit: str, ok: bool, bar: str,
             fmt: str = "{:,.3f}") -> None:
    """A figure beside its issue's bar, marked ``ok`` or ``NOT MET``."""
    t.add(f"{what}  [{bar}: {'ok' if ok else 'NOT MET'}]", value, unit, fmt)


def moto_s3(bucket: str) -> Iterator:
    """An S3 server (moto's, a process of its own on 127.0.0.1) with ``bucket`` made, the
    ``AWS_*`` variables pointing this process (and its children) at it: yields the fsspec
    filesystem; all undone after."""
    import socket
    import subprocess
    import sys

    import fsspec

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = int(s.getsockname()[1])
    moto = subprocess.Popen([sys.executable, "-m", "moto.server", "-H", "127.0.0.1", "-p",
                             str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    env = {"AWS_ACCESS_KEY_ID": "bench", "AWS_SECRET_ACCESS_KEY": "bench",
           "AWS_DEFAULT_REGION": "us-east-1", "AWS_ENDPOINT_URL": f"http://127.0.0.1:{port}"}  # fmt: skip
    before = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        fs = fsspec.filesystem("s3", skip_instance_cache=True)
        for _ in range(300):  # until the server answers
            try:
                fs.mkdir(bucket)
                break
            except OSError:
                time.sleep(0.1)
        yield fs
    finally:
        moto.terminate()
        moto.wait(30)
        for k, v in before.items():
            os.environ.pop(k) if v is None else os.environ.__setitem__(k, v)
