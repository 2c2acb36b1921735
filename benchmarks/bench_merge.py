"""`workstation merge` with the joint estimate (issue #62): B1's walks (../shared/data/
microsoft-ilc2020-site1-b1, run from their first fix on the graph of their taps) merged as a
whole process, 30, 60 and all 157 maps, then the maps replicated to 1,000 (times shifted, each
copy's points moved by up to 1 m): walks against seconds (median of 3, with the spread), and
the growth from the smallest to the largest."""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import SHARED_DATA, Table

B1 = SHARED_DATA / "microsoft-ilc2020-site1-b1" / "path_data_files"


def _maps(tmp: Path) -> list[Path]:
    from workstation.cli import main
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    files = sorted(B1.glob("*.gz"))
    graph, _ = graph_from_walks([load_session(f) for f in files])
    g = tmp / "graph.yaml"
    graph.save(g)
    import contextlib
    import io

    out = []
    for f in files:
        d = tmp / f.name.split(".")[0]
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            code = main(["run", str(f), "--graph", str(g), "--start", "first-fix", "--out", str(d)])
        if code == 0:
            out.append(d / "radiomap.csv")
    return out


def _replicate(maps: list[Path], n: int, tmp: Path) -> list[Path]:
    import pandas as pd

    rng = np.random.default_rng(0)
    out = []
    for i in range(n):
        src = maps[i % len(maps)]
        head = [ln for ln in src.read_text().splitlines()[:3] if ln.startswith("#")]
        df = pd.read_csv(src, comment="#")
        df["x"] += rng.uniform(-1, 1)
        df["y"] += rng.uniform(-1, 1)
        df["t"] += 3600.0 * (i // len(maps))
        p = tmp / f"rep{i:05d}.csv"
        p.write_text("\n".join(head) + ("\n" if head else "") + df.to_csv(index=False))
        out.append(p)
    return out


def _merge_s(maps: list[Path], tmp: Path) -> list[float]:
    ts = []
    for _ in range(3):
        tick = time.perf_counter()
        subprocess.run([sys.executable, "-m", "workstation", "merge", *map(str, maps), "-o",
                        str(tmp / "merged.csv")], check=True, capture_output=True)  # fmt: skip
        ts.append(time.perf_counter() - tick)
    return ts


def run() -> Table:
    t = Table("Issue #62: merge with the joint estimate, walks vs seconds (B1, whole process)")
    if not B1.is_dir():
        t.add(f"{B1} absent, left out", 0, "", "{:,.0f}")
        return t
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        maps = _maps(tmp)
        sizes = [(30, maps[:30]), (60, maps[:60]), (len(maps), maps)]
        sizes.append((1000, _replicate(maps, 1000, tmp)))
        first = None
        for n, ms in sizes:
            ts = sorted(_merge_s(ms, tmp))
            first = first or (n, ts[1])
            bar = {len(maps): ("≤ 10 s", ts[1] <= 10), 1000: ("≤ 120 s", ts[1] <= 120)}.get(n)
            what = f"merge {n} maps, median (min {ts[0]:.1f}, max {ts[2]:.1f})"
            if bar:
                what += f"  [{bar[0]}: {'ok' if bar[1] else 'NOT MET'}]"
            t.add(what, ts[1], "s", "{:,.1f}")
        n0, s0 = first
        t.add(f"growth {n0} → 1,000 walks: seconds ratio / walks ratio", (ts[1] / s0) / (1000 / n0),
              "(1 = linear)", "{:,.2f}")  # fmt: skip
    return t


if __name__ == "__main__":
    run().print()
