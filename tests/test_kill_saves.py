"""Saves that survive a kill (issue #18): a process saving a graph and exporting a radio map
over and over is SIGKILLed at random moments; every time, each file is a whole version (never
missing, empty or torn) and its ``.bak`` a whole earlier version (the previous one, or for the
instant between the two renames the same one)."""

import os
import signal
import time

import numpy as np
import pandas as pd
import pytest

from workstation.export import write_radiomap
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph

TRIALS = 60


def _graph(v: int) -> LandmarkGraph:
    nodes = [
        {"id": f"N{i}", "x": float(i), "y": 0.0, "floor": 0, "name": f"v{v}"} for i in range(40)
    ]
    edges = [{"from": f"N{i}", "to": f"N{i + 1}"} for i in range(39)]
    return LandmarkGraph.from_dict({"nodes": nodes, "edges": edges})


def _radiomap(v: int) -> pd.DataFrame:
    n = 100
    df = pd.DataFrame({"x": np.full(n, float(v)), "y": np.arange(n, dtype=float),
                       "floor": np.zeros(n)})  # fmt: skip
    aps = pd.DataFrame(-60.0 - np.arange(n * 10).reshape(n, 10) % 40,
                       columns=[f"02:00:00:00:00:{i:02x}" for i in range(10)])  # fmt: skip
    return pd.concat([df, aps], axis=1)


def _graph_version(path) -> int:
    g = LandmarkGraph.load(path)
    names = {n.name for n in g.nodes}
    assert len(names) == 1 and len(g.nodes) == 40, "a torn graph"
    return int(names.pop()[1:])


def _map_version(path) -> int:
    fp = Fingerprints.read(path)
    assert len(fp) == 100 and fp.rss.shape == (100, 10), "a torn radio map"
    assert np.all(fp.x == fp.x[0])
    return int(fp.x[0])


def _saver(d, start: int, done: int) -> None:  # the child: save both, forever, until killed
    v = start
    while True:
        _graph(v).save(d / "graph.yaml")
        write_radiomap(_radiomap(v), d / "map.csv")
        os.write(done, b".")  # one round saved (the parent may wait for it)
        v += 1


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_files_are_whole_after_a_kill_at_any_moment(tmp_path):
    rng = np.random.default_rng(7)
    t0 = time.perf_counter()
    _graph(0).save(tmp_path / "graph.yaml")
    write_radiomap(_radiomap(0), tmp_path / "map.csv")
    # kill moments spread over a few save rounds, however fast or loaded this machine is
    window = 4.0 * max(time.perf_counter() - t0, 0.005)
    seen = {"graph.yaml": (0, None), "map.csv": (0, None)}  # (version, .bak version)
    saved, waited = 0, 0
    for trial in range(TRIALS):
        start = max(v for v, _ in seen.values()) + 1
        rounds = int(rng.integers(0, 3))  # saves the kill waits for: whatever the machine's load
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child never returns
            try:
                os.close(r)
                _saver(tmp_path, start, w)
            finally:
                os._exit(0)
        os.close(w)
        for _ in range(rounds):  # (a read blocks until the child says a round is saved)
            assert os.read(r, 1) == b"."
        time.sleep(float(rng.uniform(0.0, window)))  # then any moment of the rounds after
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        os.close(r)
        waited += rounds > 0
        for name, version in (("graph.yaml", _graph_version), ("map.csv", _map_version)):
            path = tmp_path / name
            assert path.is_file() and path.stat().st_size > 0, (trial, name)
            v = version(path)
            bak = path.with_name(name + ".bak")
            b = version(bak) if bak.exists() else None
            pv, pb = seen[name]
            if v == pv:  # no save finished: as before, or killed between the two renames
                ok = b in (pb, pv)
            else:  # saved: the .bak is the version before the last save (or the same file)
                ok = v >= start and b in {v, v - 1 if v > start else pv}
            assert ok, (trial, name, (pv, pb), (v, b), start)
            seen[name] = (v, b)
        # no temporary file is left behind but the ones being written at the kill
        assert len([p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]) <= 2
        for p in tmp_path.glob(".*.tmp"):
            p.unlink()
        saved += seen["graph.yaml"][0] >= start
    assert saved >= waited >= TRIALS // 3  # every kill after a round saved found it saved
