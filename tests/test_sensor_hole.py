"""Walks that are not walks (issue #55 item 6): two recordings re-timed onto one clock leave a
hole in the inertial streams — nothing says where the walker went meanwhile, and the second
recording's points land where the first ended (two mall walks joined so: 1–103 m off, exit 0
before). Such a walk is quarantined (``sensor_hole``) with where the hole is, and
``workstation split`` cuts it there into two walks that each run on their own."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.pipeline.verdict import EXIT_QUARANTINED, MAX_HOLE_S, sensor_hole
from workstation.session import load_session

MSILC = REPO / "tests" / "data" / "msilc"
GRAPH = MSILC / "site1_f1_graph.yaml"


def _shifted(record, dt: float):
    return dataclasses.replace(record, t=np.asarray(record.t) + dt)


def _cat(a, b):
    """Two records of one kind, rows of ``b`` after ``a``'s."""
    n_a, n_b = len(a.t), len(b.t)
    out = {}
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) and isinstance(y, np.ndarray) and len(x) == n_a and len(y) == n_b:
            out[f.name] = np.concatenate([x, y])
    return dataclasses.replace(a, **out)


def joined(a, b, gap_s: float):
    """Walk ``b`` re-timed to start ``gap_s`` after ``a`` ends, in one session."""
    dt = a.end + gap_s - b.start
    parts = {}
    for name in ("accelerometer", "gyroscope", "magnetometer", "wifi", "ground_truth"):
        parts[name] = _cat(getattr(a, name), _shifted(getattr(b, name), dt))
    return dataclasses.replace(a, pressure=None, **parts)


def test_the_longest_pause_of_the_streams_where_it_begins():
    t = np.arange(0, 10, 0.02)
    gyro = np.concatenate([t[t < 4], t[t >= 5.2]])  # 1.2 s without the gyroscope from 4 s
    at, length = sensor_hole([t + 0.5, gyro])
    assert at == pytest.approx(3.98, abs=0.01) and length == pytest.approx(1.22, abs=0.01)
    assert sensor_hole([t])[1] == pytest.approx(0.02)


def test_no_real_walk_here_has_a_hole():
    """The rule's margin: the bundled walks (simulated and real) pause at most 0.1 s."""
    walks = sorted(MSILC.glob("*.txt.gz")) + [
        p.parent for p in (REPO / "sample_sessions").rglob("session.yaml")
    ]
    holes = []
    for w in walks:
        s = load_session(w)
        holes.append((sensor_hole([s.accelerometer.t, s.gyroscope.t]) or (0.0, 0.0))[1])
    assert len(walks) >= 15 and max(holes) < MAX_HOLE_S / 4


@pytest.mark.parametrize("pair", [(0, 1), (3, 7), (8, 2)])
def test_two_walks_joined_are_quarantined_and_split_back(tmp_path, capsys, pair):
    from workstation.session.native import write_session

    files = sorted(MSILC.glob("*.txt.gz"))
    a, b = (load_session(files[i]) for i in pair)
    write_session(joined(a, b, 1.0), tmp_path / "joined")
    out = tmp_path / "run"
    code = main(["run", str(tmp_path / "joined"), "--graph", str(GRAPH), "--start", "first-fix",
                 "--out", str(out)])  # fmt: skip
    assert code == EXIT_QUARANTINED
    said = json.loads((out / "summary.json").read_text())
    assert "sensor_hole" in [q["reason"] for q in said["quarantine"]]
    assert said["sensor_hole_s"] == pytest.approx(1.0, abs=0.05)
    ends = a.end - min(a.accelerometer.t[0], a.gyroscope.t[0])
    assert said["sensor_hole_at_s"] == pytest.approx(ends, abs=0.1)
    assert "workstation split" in capsys.readouterr().out
    # cut where the quarantine says: each part is the walk it was, and runs on its own
    assert main(["split", str(tmp_path / "joined"), "--out", str(tmp_path / "parts")]) == 0
    for i, original in ((1, a), (2, b)):
        part = load_session(tmp_path / "parts" / f"joined-{i}")
        assert len(part.accelerometer) == len(original.accelerometer)
        assert part.wifi.n_scans == original.wifi.n_scans
        assert len(part.ground_truth) == len(original.ground_truth)
        code = main(["run", str(tmp_path / "parts" / f"joined-{i}"), "--graph", str(GRAPH),
                     "--start", "first-fix", "--out", str(tmp_path / f"part{i}")])  # fmt: skip
        held = json.loads((tmp_path / f"part{i}" / "summary.json").read_text())["quarantine"]
        assert "sensor_hole" not in [q["reason"] for q in held]
    # nothing is written over: the same command again refuses, naming the folder
    assert main(["split", str(tmp_path / "joined"), "--out", str(tmp_path / "parts")]) == 2
    assert "joined-1 exists" in capsys.readouterr().err


def test_split_without_a_hole_asks_where(tmp_path, capsys):
    walk = sorted(MSILC.glob("*.txt.gz"))[0]
    assert main(["split", str(walk), "--out", str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err
    assert "never paused" in err and "--at" in err and not (tmp_path / "p").exists()
    assert main(["split", str(walk), "--out", str(tmp_path / "p"), "--at", "12.5"]) == 0
    s1, s2 = (load_session(tmp_path / "p" / f"{walk.name[:-7]}-{i}") for i in (1, 2))
    t0 = load_session(walk).accelerometer.t[0]
    assert s1.accelerometer.t[-1] < t0 + 12.5 <= s2.accelerometer.t[0]
    assert main(["split", str(walk), "--out", str(tmp_path / "q"), "--at", "1e6"]) == 2
    assert "without accelerometer or gyroscope samples" in capsys.readouterr().err
