"""A campaign from object storage against the same from disk (issue #54 item 6): the mall
floor's 106 walks (../shared/data) on a Dask LocalCluster of 2 workers, every walk run from
scratch — once walks and output on this disk, once both in an S3 bucket (moto's server, its
own process on 127.0.0.1: the store's requests cross a socket as they would to a real one).

Printed for each: wall time of the whole campaign, the walk runs' own time (in the store, a
worker reads the walk and writes its maps there), the overhead per run, and the bytes through
the loopback device (/proc/net/dev: Dask's traffic in both, the store's too in the second)."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from _common import SHARED_DATA, Table, moto_s3


def _loopback_bytes() -> int:
    for line in Path("/proc/net/dev").read_text().splitlines():
        name, _, rest = line.partition(":")
        if name.strip() == "lo":
            return int(rest.split()[0])  # received = sent on the loopback
    return 0


def run() -> Table:
    t = Table("Campaign in object storage: mall F1 from an S3 bucket vs from disk, 2 workers")
    walks = sorted((SHARED_DATA / "microsoft-ilc2020-site1-f1" / "path_data_files").glob("*"))
    try:
        import s3fs  # noqa: F401
        import upath  # noqa: F401
        from moto import server  # noqa: F401
    except ImportError:
        t.add("(s3fs, universal_pathlib and moto not installed: pip install -e .[dev])", 0, "")
        return t
    if not walks:
        t.add("(../shared/data/microsoft-ilc2020-site1-f1 absent)", 0, "")
        return t
    with tempfile.TemporaryDirectory() as tmp:
        root = _campaign(Path(tmp), walks)
        _one(t, "disk", str(root), str(Path(tmp) / "out"), len(walks))
        import fsspec

        with moto_s3("bench") as fs:
            fs.put(str(root) + "/", "bench/c/", recursive=True)
            size = sum(fs.du("bench/c/", total=False).values())
            t.add("   walks and graph uploaded", size / 1e6, "MB")
            _one(t, "S3 bucket", "s3://bench/c/", "s3://bench/out/", len(walks))
            t.add("   objects the campaign wrote", len(fs.find("bench/out/")), "", "{:,.0f}")
            here = _parts(fsspec.filesystem("file"), str(Path(tmp) / "out" / "radiomap"))
            same = here == _parts(fs, "bench/out/radiomap")
            t.add(f"   merged maps byte-identical to disk's ({len(here)} floor files)", same, "",
                  "{}")  # fmt: skip
    return t


def _parts(fs, root: str) -> dict[str, bytes]:
    return {f[len(root) :].rsplit("/", 1)[0]: fs.cat(f) for f in sorted(fs.find(root))}


def _campaign(tmp: Path, walks: list[Path]) -> Path:
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    b = tmp / "c" / "buildings" / "mall"
    (b / "walks").mkdir(parents=True)
    graph_from_walks([load_session(w) for w in walks])[0].save(b / "graph.yaml")
    for w in walks:
        (b / "walks" / w.name).symlink_to(w)
    return tmp / "c"


def _one(t: Table, where: str, campaign: str, out: str, n: int) -> None:
    from workstation.campaign import run_campaign

    lo, t0 = _loopback_bytes(), time.perf_counter()
    rep = run_campaign(campaign, out, workers=2, force=True, say=lambda s: None)
    whole, lo = time.perf_counter() - t0, _loopback_bytes() - lo
    t.add(f"{where}: {n} walks, {rep.runs} walk runs, whole campaign", whole, "s")
    t.add("   the passes' wall time", rep.wall_seconds, "s")
    t.add("   a walk run's own time (mean)", 1e3 * rep.busy_seconds / rep.runs, "ms")
    t.add("   overhead per run beyond its own time / 2 workers",
          1e3 * (rep.wall_seconds - rep.busy_seconds / 2) / rep.runs, "ms")  # fmt: skip
    t.add("   bytes through the loopback device", lo / 1e6, "MB")


if __name__ == "__main__":
    run().print()
