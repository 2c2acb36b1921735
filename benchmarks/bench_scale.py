"""Issue #66: a campaign of 100 → 1,000 → 10,000 walks on this machine, 2 workers (a Dask
LocalCluster): walks per second, the client's peak memory, each pass's wall seconds
(campaign.json's ``pass_seconds``) and how each grows from 1,000 to 10,000 walks; the 1,000-walk
run's merged maps against a run with one worker; the same 1,000 walks from an S3 bucket (moto's
server) against disk.

The walks: the four mall floors' (../shared/data, 462 walks, one building per floor, its graph
from its walks' taps) replicated — copy r of a walk has every timestamp of its file (the
readings, the WiFi "last seen", the header's start and end) moved r × 10⁸ ms (1.16 days) later,
so copies are different walks recorded on different days. Made once, uncompressed, under
``$SCALE_CACHE`` (the temp folder by default; 10,000 walks ≈ 6 GB).

    python benchmarks/run.py scale               # SCALE_WALKS=100,1000,10000 by default

Each size runs in a process of its own (its peak memory is its own: ru_maxrss).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import SHARED_DATA, Table, moto_s3
from bench_startup import sample_run

FLOORS = ("f1", "f2", "f3", "b1")
SHIFT_MS = 10**8  # copy r of a walk: every timestamp r × this later
_TIME = re.compile(rb"(?<=[\n\t:])(1[5-7]\d{3})(?=\d{8}(?![\d.]))")


def _sizes() -> list[int]:
    return [int(v) for v in os.environ.get("SCALE_WALKS", "100,1000,10000").split(",")]


def _cache() -> Path:
    return Path(os.environ.get("SCALE_CACHE", tempfile.gettempdir())) / "workstation-scale"


def _shifted(src: Path, dst: Path, r: int) -> None:
    """``src`` (a gzipped path file) with every epoch-ms timestamp r × ``SHIFT_MS`` later."""
    import gzip

    data = gzip.decompress(src.read_bytes())
    if r:
        data = _TIME.sub(lambda m: str(int(m.group(1)) + r).encode(), data)
    tmp = dst.with_suffix(".part")
    tmp.write_bytes(data)
    tmp.replace(dst)


def campaign(n: int) -> Path:
    """The campaign folder of ``n`` walks (made, or found made): one building per floor."""
    import itertools

    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    per = [[(f, p) for p in sorted(
        (SHARED_DATA / f"microsoft-ilc2020-site1-{f}" / "path_data_files").glob("*.gz"))]
        for f in FLOORS]  # fmt: skip
    # the floors in turn, so that every size has walks of each
    base = [w for w in itertools.chain(*itertools.zip_longest(*per)) if w is not None]
    root = _cache() / f"c{n}"
    if (root / "done").is_file():
        return root
    shutil.rmtree(root, ignore_errors=True)
    for f in FLOORS:
        g = _cache() / "graphs" / f"{f}.yaml"
        if not g.is_file():
            g.parent.mkdir(parents=True, exist_ok=True)
            walks = [load_session(p) for ff, p in base if ff == f]
            graph_from_walks(walks)[0].save(g)
        (root / "buildings" / f / "walks").mkdir(parents=True)
        shutil.copy(g, root / "buildings" / f / "graph.yaml")
    for i in range(n):
        r, (f, p) = divmod(i, len(base))[0], base[i % len(base)]
        walk = _cache() / "walks" / f / f"r{r:03d}_{p.name[:-3]}"
        if not walk.is_file():
            walk.parent.mkdir(parents=True, exist_ok=True)
            _shifted(p, walk, r)
        (root / "buildings" / f / "walks" / walk.name).symlink_to(walk)
    (root / "done").write_text(str(n))
    return root


def _one(root: str, out: str, workers: int) -> dict:
    """A campaign run from scratch in a process of its own: its report's figures and the
    process's peak memory."""
    got = subprocess.run([sys.executable, __file__, "--one", root, out, str(workers)],
                         capture_output=True, text=True, env=os.environ.copy())  # fmt: skip
    if got.returncode != 0:
        raise RuntimeError(f"campaign of {root} failed: {got.stderr[-2000:]}")
    return json.loads(got.stdout.strip().splitlines()[-1])


def _main_one(root: str, out: str, workers: int) -> None:
    import resource
    import time

    from workstation.campaign import run_campaign

    t0 = time.perf_counter()
    rep = run_campaign(root, out, workers=workers, force=True, say=lambda s: None)
    whole = time.perf_counter() - t0  # (the report's steps too)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    print(json.dumps({"walks": rep.walks, "ok": rep.walks_ok, "runs": rep.runs,
                      "wall": whole, "passes": dict(rep.pass_seconds),
                      "peak_bytes": peak}))  # fmt: skip


def _same_maps(a: Path, b: Path) -> bool:
    import pandas as pd

    def frame(p: Path):
        df = pd.read_parquet(p / "radiomap")
        df = df[sorted(df.columns, key=str)]
        return df.sort_values(["building", "floor", "x", "y"]).reset_index(drop=True)

    try:
        pd.testing.assert_frame_equal(frame(a), frame(b))
        return True
    except AssertionError:
        return False


def run() -> Table:
    t = Table("Issue #66: a campaign of many walks (the mall's floors replicated), 2 workers")
    sample_run(t)  # one walk, whole process, as bench_startup times it
    if not any((SHARED_DATA / f"microsoft-ilc2020-site1-{f}").is_dir() for f in FLOORS):
        t.add("(../shared/data's mall floors absent)", 0, "")
        return t
    got = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in _sizes():
            root = campaign(n)
            r = got[n] = _one(str(root), str(Path(tmp) / f"out{n}"), 2)
            t.add(f"{n:,} walks: {r['ok']:,} ok, {r['runs']:,} walk runs, whole campaign", r["wall"], "s")
            t.add("   walks per second", r["walks"] / r["wall"], "walks/s")
            t.add(f"   the client's peak memory  [≤ 2 GB: "
                  f"{'ok' if r['peak_bytes'] <= 2e9 else 'NOT MET'}]", r["peak_bytes"] / 1e9, "GB",
                  "{:,.2f}")  # fmt: skip
            for name, sec in r["passes"].items():
                t.add(f"   {name}", sec, "s", "{:,.2f}")
        big = [n for n in _sizes() if n >= 1000]
        if len(big) >= 2:
            lo, hi = big[0], big[-1]
            for name, sec in got[hi]["passes"].items():
                before = got[lo]["passes"].get(name, 0.0)
                if before >= 0.5:  # (below half a second the ratio says little)
                    g = sec / before / (hi / lo)
                    t.add(f"growth {lo:,} → {hi:,}: {name} ÷ linear  [≤ 3: "
                          f"{'ok' if g <= 3 else 'NOT MET'}]", g, "×", "{:,.2f}")  # fmt: skip
        if 1000 in got:
            one = _one(str(campaign(1000)), str(Path(tmp) / "out1000_one"), 1)
            same = _same_maps(Path(tmp) / "out1000", Path(tmp) / "out1000_one")
            t.add(f"1,000 walks, one worker: wall {one['wall']:.0f} s; merged maps identical to "
                  f"2 workers'  [{'ok' if same else 'NOT MET'}]", float(same), "", "{:.0f}")  # fmt: skip
            _s3(t, got[1000]["wall"])
    return t


def _s3(t: Table, disk_wall: float) -> None:
    """The 1,000-walk campaign from and into an S3 bucket (moto's server, its own process)."""
    try:
        import s3fs  # noqa: F401
        import upath  # noqa: F401
        from moto import server  # noqa: F401
    except ImportError:
        t.add("(s3fs, universal_pathlib and moto not installed: pip install -e .[dev])", 0, "")
        return
    with moto_s3("scale") as fs:
        root = campaign(1000)
        for b in sorted((root / "buildings").iterdir()):
            walks = sorted((b / "walks").iterdir())
            fs.put(str(b / "graph.yaml"), f"scale/c/buildings/{b.name}/graph.yaml")
            fs.put([str(w.resolve()) for w in walks],
                   [f"scale/c/buildings/{b.name}/walks/{w.name}" for w in walks])  # fmt: skip
        r = _one("s3://scale/c/", "s3://scale/out/", 2)
        ratio = r["wall"] / disk_wall
        t.add(f"1,000 walks from and into an S3 bucket: wall {r['wall']:.0f} s ÷ disk's  "
              f"[≤ 1.5: {'ok' if ratio <= 1.5 else 'NOT MET'}]", ratio, "×", "{:,.2f}")  # fmt: skip


if __name__ == "__main__":
    if sys.argv[1:2] == ["--one"]:
        _main_one(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    else:
        run().print()
