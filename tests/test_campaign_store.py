"""Campaigns whose walks and maps live in object storage (issue #54), against a real
S3-compatible server (moto's, on 127.0.0.1) and a Dask scheduler with two worker processes
started here, each in a folder of its own: the campaign is uploaded and its local copy deleted,
so the workers can only read the walks from the bucket and write the maps back there.

- the two-building campaign, killed mid-run and run again, finishes with every walk run once,
  and its merged maps are byte for byte those of the same campaign run from disk;
- ``localize --map s3://…/radiomap/building=…`` gives the local map's figures;
- a second run on the same prefix is refused while the first holds it;
- a missing bucket, no credentials, a walk gone from the bucket and a cut ``.gz``: one line
  naming the URL, exit non-zero, the other walks kept."""

from __future__ import annotations

import gzip
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from tests.conftest import REPO
from tests.s3 import local_s3, need_store, without_credentials
from tests.test_campaign import _campaign
from workstation.cli import main

need_store("distributed")

MSILC = REPO / "tests" / "data" / "msilc"
HELD = REPO / "sample_sessions" / "office2f" / "heldout"


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """(scheduler address, the store's environment): a bucket ``camp``; a scheduler and two
    single-thread workers, each process started in a folder of its own."""
    import fsspec
    from distributed import Client

    with local_s3() as env:
        fsspec.filesystem("s3").mkdir("camp")
        home = tmp_path_factory.mktemp("cluster")
        sfile = home / "scheduler.json"
        # the code under test, as installed on every machine of a cluster (the package's
        # digest keys each walk's result: the client and its workers must run this code)
        penv = {**os.environ, **env, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPATH": str(REPO)}
        procs = [_start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                         "--no-dashboard", "--scheduler-file", str(sfile)],
                        home / "scheduler", penv)]  # fmt: skip
        try:
            for _ in range(600):
                if sfile.is_file() and sfile.stat().st_size:
                    break
                time.sleep(0.1)
            address = json.loads(sfile.read_text())["address"]
            for i in (1, 2):
                procs.append(_start(["distributed.cli.dask_worker", address, "--nthreads", "1",
                                     "--no-dashboard", "--host", "127.0.0.1", "--local-directory",
                                     str(home / f"worker{i}")], home / f"worker{i}",
                                    penv))  # fmt: skip
            with Client(address) as c:
                c.wait_for_workers(2, timeout=120)
                assert {w["local_directory"].startswith(str(home / "worker"))
                        for w in c.scheduler_info()["workers"].values()} == {True}  # fmt: skip
            yield address, env
        finally:
            for p in procs[::-1]:
                p.terminate()
            for p in procs:
                try:
                    p.wait(30)
                except subprocess.TimeoutExpired:
                    p.kill()


def _start(argv, cwd, env) -> subprocess.Popen:
    cwd.mkdir(parents=True, exist_ok=True)
    return subprocess.Popen([sys.executable, "-m", *argv], cwd=cwd, env={**env, "HOME": str(cwd)},
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip


def _parts(fs_root: str, fs) -> dict[str, bytes]:
    """Each floor of each building's merged map: its Parquet's bytes (one file a floor)."""
    out = {}
    for f in sorted(fs.find(fs_root)):
        rel = f[len(fs_root) :].lstrip("/")
        out[rel.rsplit("/", 1)[0]] = fs.cat(f)
    return out


def test_a_campaign_from_a_bucket_killed_and_resumed_matches_the_local_run(
    cluster, tmp_path, capsys
):
    import fsspec

    from workstation.campaign import run_campaign

    address, env = cluster
    s3 = fsspec.filesystem("s3")
    root = _campaign(tmp_path)
    local = run_campaign(root, tmp_path / "local", scheduler=address, say=lambda _: None)
    s3.put(str(root) + "/", "camp/c1/", recursive=True)
    shutil.rmtree(root)  # the client has no copy now; the workers never had one

    client_dir = tmp_path / "client"
    client_dir.mkdir()
    proc = subprocess.Popen(
        [sys.executable, "-m", "workstation", "campaign", "run", "s3://camp/c1/", "--out",
         "s3://camp/out1/", "--scheduler", address],
        cwd=client_dir, env={**os.environ, **env, "PYTHONPATH": str(REPO)}, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip
    done: dict = {}
    for _ in range(1200):  # killed as soon as the first walk is committed
        if s3.exists("camp/out1/state.json"):
            done = json.loads(s3.cat("camp/out1/state.json"))
            if done:
                break
        time.sleep(0.05)
    alive = proc.poll() is None
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert done and alive, "the campaign finished before it could be killed"
    done = json.loads(s3.cat("camp/out1/state.json"))  # what it had committed when killed
    first = [k for k in done if "@" not in k]
    assert s3.exists("camp/out1/campaign.lock")  # left by the killed run

    lines: list[str] = []
    s3.invalidate_cache()
    again = run_campaign("s3://camp/c1/", "s3://camp/out1/", scheduler=address,
                         say=lines.append)  # fmt: skip
    assert any("taking over" in ln and "finished in its last second run again" in ln
               for ln in lines), lines
    # every walk once: what the killed run committed is not redone, the rest is run now
    assert again.run_now == local.walks - len(first)
    assert again.walks == local.walks and again.walks_ok == local.walks_ok
    assert not s3.exists("camp/out1/campaign.lock")
    # known unchanged by their objects' ETags: nothing again; a walk changed in the bucket: it
    assert run_campaign("s3://camp/c1/", "s3://camp/out1/", scheduler=address,
                        say=lines.append).run_now == 0  # fmt: skip
    s3.pipe("camp/c1/buildings/office/walks/broken.txt", b"still not a walk\n")
    assert run_campaign("s3://camp/c1/", "s3://camp/out1/", scheduler=address,
                        say=lines.append).run_now == 1  # fmt: skip
    # the merged maps, byte for byte those of the local run
    there = _parts("camp/out1/radiomap", s3)
    here = _parts(str(tmp_path / "local" / "radiomap"), fsspec.filesystem("file"))
    assert there == here and len(here) >= 3
    assert {b: r.reference_points for b, r in again.buildings.items()} == {
        b: r.reference_points for b, r in local.buildings.items()
    }
    # localize on the building's map in the store: the local map's figures
    argv = ["localize", "--session", str(HELD), "--map"]
    capsys.readouterr()
    assert main([*argv, str(tmp_path / "local" / "radiomap" / "building=office")]) == 0
    mine = capsys.readouterr().out
    assert main([*argv, "s3://camp/out1/radiomap/building=office"]) == 0
    theirs = capsys.readouterr().out
    assert "mean" in mine and theirs.replace(
        "s3://camp/out1/radiomap/building=office",
        str(tmp_path / "local" / "radiomap" / "building=office"),
    ) == mine  # fmt: skip


def test_a_second_run_on_the_same_prefix_is_refused(cluster, capsys):
    from workstation.campaign.lock import CampaignLock
    from workstation.io.store import place

    out = place("s3://camp/busy/", cached=False)
    with CampaignLock(out, say=print):
        code = main(["campaign", "run", "s3://camp/none/", "--out", "s3://camp/busy/"])
        err = capsys.readouterr().err
    # (the campaign is read first: a missing one is said before the lock is looked at)
    assert code == 2 and "s3://camp/none" in err
    import fsspec

    s3 = fsspec.filesystem("s3")
    s3.pipe("camp/c2/buildings/office/graph.yaml", (REPO / "sample_sessions" / "office2f" /
            "normal" / "graph.yaml").read_bytes())  # fmt: skip
    s3.put(str(HELD) + "/", "camp/c2/buildings/office/walks/heldout/", recursive=True)
    with CampaignLock(out, say=print):
        code = main(["campaign", "run", "s3://camp/c2/", "--out", "s3://camp/busy/"])
        err = capsys.readouterr().err
    assert code == 2 and "another campaign run is writing here" in err
    assert err.startswith("error: s3://camp/busy/campaign.lock") and len(err.splitlines()) == 1
    assert not s3.exists("camp/busy/state.json")  # nothing of the refused run written


def test_bad_store_input_is_one_line_naming_the_url(cluster, capsys, monkeypatch):
    import fsspec

    address, _ = cluster
    code = main(["campaign", "run", "s3://nobucket/c/", "--out", "s3://camp/o3/"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: s3://nobucket/c") and len(err.splitlines()) == 1
    # walks listed in a campaign file: one cut short mid-upload, one gone from the bucket
    s3 = fsspec.filesystem("s3")
    good, cut = sorted(MSILC.glob("*.txt.gz"))[:2]
    s3.put(str(good), f"camp/y/{good.name}")
    s3.pipe("camp/y/cut.txt.gz", cut.read_bytes()[:60_000])
    s3.put(str(MSILC / "site1_f1_graph.yaml"), "camp/y/graph.yaml")
    s3.pipe("camp/y/campaign.yaml", json.dumps({"buildings": {"mall": {
        "graph": "graph.yaml", "walks": [good.name, "cut.txt.gz", "gone.txt.gz"],
        "start": "infer"}}}).encode())  # fmt: skip
    code = main(["campaign", "run", "s3://camp/y/campaign.yaml", "--out", "s3://camp/o4/",
                 "--scheduler", address])  # fmt: skip
    out = capsys.readouterr()
    assert code == 1 and "Traceback" not in out.err + out.out
    walks = {w["key"]: w for w in json.loads(s3.cat("camp/o4/campaign.json"))["per_walk"]}
    assert walks[f"mall/{good.name[:-7]}"]["status"] == "ok"
    assert walks["mall/cut"]["error"].startswith("InputError: s3://camp/y/cut.txt.gz")
    assert "truncated" in walks["mall/cut"]["error"]
    assert walks["mall/gone"]["error"] == (
        "Unreadable: s3://camp/y/gone.txt.gz: no such object, prefix or bucket"
    )
    # gone from the store: tried again on the next run; cut short: what the file holds, kept
    assert walks["mall/gone"].get("retry") and not walks["mall/cut"].get("retry")
    gzip.decompress(s3.cat(f"camp/y/{good.name}"))  # the store's walk itself untouched
    # no credentials: one line naming the campaign's URL
    without_credentials(monkeypatch)
    code = main(["campaign", "run", "s3://camp/y/campaign.yaml", "--out", "s3://camp/o5/"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: s3://camp/y/campaign.yaml") and "credentials" in err
    assert len(err.strip().splitlines()) == 1 and "testing" not in err


def test_on_disk_too_one_run_writes_an_output_and_a_dead_ones_lock_is_taken_over(tmp_path):
    from workstation.campaign import run_campaign
    from workstation.campaign.lock import NAME, CampaignLock
    from workstation.errors import InputError

    root, out = _campaign(tmp_path), tmp_path / "out"
    with CampaignLock(out, say=print), pytest.raises(InputError, match="another campaign run"):
        run_campaign(root, out, workers=1, say=lambda _: None)
    assert sorted(p.name for p in out.iterdir()) == []  # refused before writing anything
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)  # fmt: skip
    (out / NAME).write_text(json.dumps({"host": os.uname().nodename, "pid": int(dead.stdout),
                                        "token": "x", "beat": 0}))  # fmt: skip
    lines: list[str] = []
    rep = run_campaign(root, out, workers=1, say=lines.append)
    assert rep.walks_ok == 4 and any("taking over" in ln for ln in lines)
    assert not (out / NAME).exists()
    (out / NAME).symlink_to("/dev/zero")  # a lock that is a device: refused, never read
    with pytest.raises(InputError, match="not a regular file"):
        run_campaign(root, out, workers=1, say=lambda _: None)
    assert (out / NAME).is_symlink()


def test_wrong_credentials_are_one_line_naming_the_url(capsys, monkeypatch):
    import s3fs

    from tests.s3 import checking_s3

    with checking_s3() as endpoint:
        monkeypatch.setenv("AWS_ENDPOINT_URL", endpoint)
        monkeypatch.setenv("AWS_ACCESS_KEY_ID", "AKIAWRONGWRONGWRONG1")
        monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "a-wrong-secret")
        monkeypatch.setenv("AWS_DEFAULT_REGION", "us-east-1")
        s3fs.S3FileSystem.clear_instance_cache()
        try:
            code = main(["campaign", "run", "s3://camp/c/", "--out", "s3://camp/o/"])
        finally:
            s3fs.S3FileSystem.clear_instance_cache()
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: s3://camp/c") and "credentials" in err
    assert len(err.strip().splitlines()) == 1 and "a-wrong-secret" not in err


def test_a_walk_run_costs_the_store_few_requests(cluster, tmp_path):
    """Issue #66: from and into a bucket a campaign took twice its time on disk — each request
    is a round trip (~10 ms to a real store). Beyond reading the walks themselves, this
    campaign (5 walks, 8 runs, two buildings) cost 249 requests, 31 a walk run: a HEAD before
    every GET, the graph's and the lock's HEADs in each worker, every walk's summary.json
    read four times by the client in three requests each, a HEAD per walk for its first map
    and its queries. Counted on the server, planning, the passes and the report together:
    at most 18 a walk run (125 now; on the mall's 6 single-file walks 10 a run)."""
    import logging
    import re

    import fsspec

    from workstation.campaign import run_campaign

    address, _ = cluster
    s3 = fsspec.filesystem("s3")
    root = _campaign(tmp_path)
    s3.put(str(root) + "/", "camp/c3/", recursive=True)
    seen: list[str] = []

    class Count(logging.Handler):
        def emit(self, record):
            seen.append(record.getMessage())

    log = logging.getLogger("werkzeug")  # the server's access log, one line a request
    handler, level = Count(), log.level
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    try:
        rep = run_campaign("s3://camp/c3/", "s3://camp/out3/", scheduler=address,
                           say=lambda _: None)  # fmt: skip
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
    # beyond reading the walks themselves (a session folder is a dozen objects)
    asked = [m for m in seen if "/camp" in m and any(v in m for v in ("GET", "HEAD", "PUT"))
             and not re.search(r"/camp/c3/buildings/[^/ ]+/walks/", m)]  # fmt: skip
    assert rep.runs == 8 and rep.walks_ok == 4
    assert len(asked) <= 18 * rep.runs, len(asked)
