"""Campaign throughput: walks per minute on a Dask LocalCluster with 1 and 2 workers (the
bundled simulated walks, copied to make a campaign of 24), and the overhead per walk beyond the
pipeline's own time (scheduling, transfer, writing results)."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from _common import REPO, Table

N_COPIES = 8  # × 3 walks


def _campaign(root: Path) -> Path:
    office = REPO / "sample_sessions" / "office2f"
    b = root / "buildings" / "office"
    (b / "walks").mkdir(parents=True)
    shutil.copy(office / "normal" / "graph.yaml", b / "graph.yaml")
    for i in range(N_COPIES):
        for w in ("normal", "varied", "heldout"):
            shutil.copytree(office / w, b / "walks" / f"{w}{i}")
    return root


def run() -> Table:
    from workstation.campaign import run_campaign

    t = Table(f"Campaign: {3 * N_COPIES} walks of 6-7 min (simulated office), Dask LocalCluster")
    with tempfile.TemporaryDirectory() as tmp:
        root = _campaign(Path(tmp) / "c")
        for workers in (1, 2):
            out = Path(tmp) / f"out{workers}"
            rep = run_campaign(root, out, workers=workers, force=True, say=lambda s: None)
            n = rep.walks_ok
            busy = sum(w["seconds"] or 0 for w in rep.per_walk)
            wall = rep.wall_seconds
            t.add(f"{workers} worker(s): walks per minute", 60 * n / wall, "walks/min")
            t.add(
                f"{workers} worker(s): overhead per walk", 1e3 * (wall - busy / workers) / n, "ms"
            )
            t.add(f"{workers} worker(s): pipeline time per walk", 1e3 * busy / n, "ms")
    return t


if __name__ == "__main__":
    run().print()
