"""Whole process, wall clock (issue #17): `workstation info` on the largest museum logfile and
`workstation run` on the bundled Microsoft walk, as a surveyor types them — imports included.
Medians of 7 runs with the interquartile range."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from _common import REPO, SHARED_DATA, Table, median_of

WS = [sys.executable, "-m", "workstation"]


def _wall(args: list[str]) -> tuple[float, float]:
    run = lambda: subprocess.run(WS + args, capture_output=True, check=True, cwd=REPO)  # noqa: E731
    run()  # warm the file cache
    return median_of(run, 7)


def run() -> Table:
    tab = Table("Whole process (wall, imports included)")
    logs = sorted((SHARED_DATA / "ipin2023-track3" / "logfiles").glob("*.txt"))
    if logs:
        big = max(logs, key=lambda f: f.stat().st_size)
        sec, iqr = _wall(["info", str(big)])
        mb = big.stat().st_size / 1e6
        tab.add(f"workstation info {big.name[:30]}… ({mb:.1f} MB), median", sec, "s", "{:.2f}")
        tab.add("   interquartile range", iqr, "s", "{:.2f}")
    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    with tempfile.TemporaryDirectory() as out:
        sec, iqr = _wall(
            ["run", str(ms), "--graph", str(ms / "graph.yaml"), "--out", str(Path(out))]
        )
    tab.add("workstation run on the bundled Microsoft walk, median", sec, "s", "{:.2f}")
    tab.add("   interquartile range", iqr, "s", "{:.2f}")
    return tab


if __name__ == "__main__":
    run().print()
