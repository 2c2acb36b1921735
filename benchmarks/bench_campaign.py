"""Campaign throughput: walks per minute on a Dask LocalCluster with 1 and 2 workers (the
bundled simulated walks, copied to make a campaign of 24), and the overhead per walk beyond the
pipeline's own time (scheduling, transfer, writing results). With ../shared/data: the mall
floor's 106 walks on 2 workers (issue #53: wall ≤ 2 × the walk runs' own time, overhead ≤ 50 ms
a run), every walk run twice (the second time with the building's map), end to end."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from _common import REPO, SHARED_DATA, Table

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
            n, runs, busy, wall = rep.walks_ok, rep.runs, rep.busy_seconds, rep.wall_seconds
            t.add(f"{workers} worker(s): walks per minute", 60 * n / wall, "walks/min")
            t.add(f"{workers} worker(s): overhead per walk run (the cluster's start included)",
                  1e3 * (wall - busy / workers) / runs, "ms")  # fmt: skip
            t.add(f"{workers} worker(s): a walk run's own time", 1e3 * busy / runs, "ms")
        _mall(t, Path(tmp))
    _in_a_worker(t)
    return t


def _in_a_worker(t: Table) -> None:
    """One 31-s mall walk as a campaign's worker runs it (its graph read once, Arrow loaded),
    start at the first fix: issue #53's bar is 1,000 × real time. In a process of its own, as
    a worker is: in the benchmarks' process, right after the mall's campaign and its report, the
    same walk took 32 ms against 28 ms here (not looked into further)."""
    import json
    import subprocess
    import sys

    got = subprocess.run([sys.executable, __file__, "--in-a-worker"], capture_output=True,
                         text=True, check=True)  # fmt: skip
    sec, iqr = json.loads(got.stdout.strip().splitlines()[-1])
    t.add("a 31-s mall walk inside a worker (first-fix), median", 1e3 * sec, "ms")
    t.add("   interquartile range", 1e3 * iqr, "ms")
    t.add("   × real time", 31.3 / sec, "×", "{:,.0f}")


def _mall(t: Table, tmp: Path) -> None:
    import time

    from workstation.campaign import run_campaign
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    walks = sorted((SHARED_DATA / "microsoft-ilc2020-site1-f1" / "path_data_files").glob("*"))
    if not walks:
        return
    b = tmp / "mall" / "buildings" / "mall"
    (b / "walks").mkdir(parents=True)
    graph_from_walks([load_session(w) for w in walks])[0].save(b / "graph.yaml")
    for w in walks:
        (b / "walks" / w.name).symlink_to(w)
    t0 = time.perf_counter()
    rep = run_campaign(tmp / "mall", tmp / "mall_out", workers=2, force=True, say=lambda s: None)
    whole = time.perf_counter() - t0
    t.add(f"mall F1, {len(walks)} walks on 2 workers: walk runs (two passes)", rep.runs, "runs",
          "{:,.0f}")  # fmt: skip
    t.add("   their own time, summed", rep.busy_seconds, "s")
    t.add("   wall (the passes)", rep.wall_seconds, "s")
    t.add("   wall / their own time", rep.wall_seconds / rep.busy_seconds, "×", "{:.2f}")
    t.add("   overhead per run beyond its own time / 2 workers",
          1e3 * (rep.wall_seconds - rep.busy_seconds / 2) / rep.runs, "ms")  # fmt: skip
    t.add("   whole campaign (the report and merged map too)", whole, "s")


def _worker_times() -> tuple[float, float]:
    import pyarrow  # noqa: F401 - loaded in every worker (the walk's maps are Parquet)
    from _common import median_of

    from workstation.campaign.jobs import WalkJob, run_walk

    walk = REPO / "tests" / "data" / "msilc" / "5dd9e7aac5b77e0006b1732b.txt.gz"  # 31.3 s
    job = WalkJob("mall", walk, walk.parent / "site1_f1_graph.yaml", None, "first-fix", "m/w", "")
    run_walk(job)
    return median_of(lambda: run_walk(job), 21)


if __name__ == "__main__":
    import sys

    if sys.argv[1:] == ["--in-a-worker"]:
        import json

        print(json.dumps(_worker_times()))
    else:
        run().print()
