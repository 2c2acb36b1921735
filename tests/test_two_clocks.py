"""Two walks joined with no pause (issue #55 item 6): the inertial sensors do not show the join,
the file's second clock does (session/clocks.py) — a GetSensorData file's sensor timestamps, a
Microsoft ILC file's "last seen" of each WiFi reading. Such a walk is quarantined
(``two_clocks``) with where the second recording begins, and ``workstation split`` cuts it
there into two walks that each run on their own. No real walk here holds such evidence."""

from __future__ import annotations

import gzip
import json

import numpy as np
import pytest
import yaml

from tests.conftest import IPIN, REPO, gsd_lines, need
from workstation.cli import main
from workstation.pipeline.verdict import EXIT_QUARANTINED, MAX_HOLE_S
from workstation.session import load_session
from workstation.session.clocks import MIN_BLOCK, block_start
from workstation.session.native import write_session

MSILC = REPO / "tests" / "data" / "msilc"
GRAPH = MSILC / "site1_f1_graph.yaml"


def _rows(path) -> tuple[list[str], list[list[str]]]:
    lines = gzip.open(path, "rt", encoding="utf-8").read().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    return head, [ln.split("\t") for ln in lines if ln[:1].isdigit()]


def join_ilc(a, b, out, careful: bool = False, phone_state: bool = True) -> float:
    """Path file ``b``'s rows re-timed to follow ``a``'s last by 20 ms (its WiFi "last seen"
    as recorded, or moved alike when ``careful``; its uncalibrated sensors' rows, which carry
    the phone's calibration, dropped unless ``phone_state``); the second recording's first
    WiFi scan, on the joined walk's clock (s)."""
    head, ra = _rows(a)
    _, rb = _rows(b)
    if not phone_state:
        rb = [r for r in rb if not r[1].endswith("_UNCALIBRATED")]
    d = max(int(r[0]) for r in ra) + 20 - min(int(r[0]) for r in rb)
    for r in rb:
        r[0] = str(int(r[0]) + d)
        if careful and r[1] == "TYPE_WIFI":
            r[6] = str(int(r[6]) + d)
    out.write_text("\n".join(head + ["\t".join(r) for r in ra + rb]) + "\n")
    start = float(next(ln for ln in head if "startTime" in ln).split("startTime:")[1].split()[0])
    return (min(int(r[0]) for r in rb if r[1] == "TYPE_WIFI") - start) / 1000.0


def quarantined_then_split_clean(joined, graph, tmp_path, capsys, evidence: str) -> None:
    """``run`` quarantines the joined walk ``two_clocks`` naming ``evidence``; ``split`` cuts it
    into two walks, neither holding a second recording, each of which runs unquarantined."""
    out = tmp_path / "run"
    assert main(["run", str(joined), "--graph", str(graph), "--out", str(out)]) == EXIT_QUARANTINED
    held = {q["reason"]: q for q in json.loads((out / "summary.json").read_text())["quarantine"]}
    assert "two_clocks" in held and evidence in held["two_clocks"]["detail"]
    capsys.readouterr()
    assert main(["split", str(joined), "--out", str(tmp_path / "parts")]) == 0
    for i in (1, 2):
        part = tmp_path / "parts" / f"{joined.stem}-{i}"
        assert load_session(part).metadata.clock_jump is None
        main(["run", str(part), "--graph", str(graph), "--out", str(tmp_path / f"o{i}")])
        said = json.loads((tmp_path / f"o{i}" / "summary.json").read_text())
        assert "two_clocks" not in [q["reason"] for q in said["quarantine"]]


def test_a_block_on_another_clock_not_a_few_stray_samples():
    t = np.arange(2000) * 0.02
    off = np.zeros(t.size, bool)
    off[[5, 700, 1500]] = True  # a sensor's glitches: not a second recording
    assert block_start(t, off) is None
    off[1200:] = True
    assert block_start(t, off) == pytest.approx(t[1200])
    off[:] = False
    off[: MIN_BLOCK + 30] = True  # the first recording on the other clock: where it ends
    assert block_start(t, off) == pytest.approx(t[MIN_BLOCK + 30])


def test_no_real_walk_here_holds_two_clocks():
    walks = sorted(MSILC.glob("*.txt.gz")) + [
        p.parent for p in (REPO / "sample_sessions").rglob("session.yaml")
    ]
    walks += sorted((IPIN / "logfiles").glob("*.txt")) if IPIN.exists() else []
    assert len(walks) >= 15
    assert [w for w in walks if load_session(w).metadata.clock_jump is not None] == []


@pytest.mark.parametrize("pair", [(0, 1), (0, 8), (8, 0), (3, 9)])
def test_two_path_files_joined_with_no_pause(tmp_path, capsys, pair):
    """Walks recorded 3 s or an hour apart, the second re-timed earlier (its scans report
    access points seen after them) or an hour later (none seen within 10 min): found where the
    second recording's first scan is, quarantined, split there, each part clean. (Recorded
    minutes before and moved later, its readings are all too old for a map —
    ``max_wifi_age_s`` — and nothing of it goes in.) The WiFi's clock alone: the second
    recording's rows that carry the phone's calibration dropped (test_phone_state.py)."""
    files = sorted(MSILC.glob("*.txt.gz"))
    joined = tmp_path / "joined.txt"
    first_scan = join_ilc(files[pair[0]], files[pair[1]], joined, phone_state=False)
    s = load_session(joined)
    assert s.metadata.clock_jump.t == pytest.approx(first_scan, abs=1e-3)
    write_session(s, tmp_path / "native")  # the evidence kept where the walk is saved
    assert load_session(tmp_path / "native").metadata.clock_jump == s.metadata.clock_jump
    gaps = [np.diff(x.t).max() for x in (s.accelerometer, s.gyroscope)]
    assert max(gaps) < MAX_HOLE_S  # no pause: the sensor_hole rule cannot see this one
    out = tmp_path / "run"
    code = main(["run", str(joined), "--graph", str(GRAPH), "--out", str(out)])
    assert code == EXIT_QUARANTINED
    assert "a second recording begins" in capsys.readouterr().out
    said = json.loads((out / "summary.json").read_text())
    held = {q["reason"]: q for q in said["quarantine"]}
    assert "two_clocks" in held and "workstation split" in held["two_clocks"]["what_to_do"]
    assert said["clock_jump_at_s"] == pytest.approx(first_scan - (s.accelerometer.t[0]), abs=0.05)
    assert main(["split", str(joined), "--out", str(tmp_path / "parts")]) == 0
    for i in (1, 2):
        part = tmp_path / "parts" / f"joined-{i}"
        meta = load_session(part).metadata
        assert meta.clock_jump is None and not any("second recording" in w for w in meta.warnings)
        main(["run", str(part), "--graph", str(GRAPH), "--out", str(tmp_path / f"o{i}")])
        said = json.loads((tmp_path / f"o{i}" / "summary.json").read_text())
        assert "two_clocks" not in [q["reason"] for q in said["quarantine"]]


@pytest.mark.parametrize("at", [2.5, 4.0, 6.0])  # the second recording shorter, as long, longer
def test_a_getsensordata_file_whose_second_part_is_on_another_sensor_clock(tmp_path, at):
    body = gsd_lines(seconds=8.0)
    moved = []
    for ln in body:
        f = ln.split(";")
        if f[0] in ("ACCE", "GYRO", "MAGN", "PRES") and float(f[1]) >= at:
            f[2] = f"{float(f[2]) + 5000.0:.4f}"  # a second phone's clock, re-timed on the app's
        moved.append(";".join(f))
    p = tmp_path / "joined.txt"
    p.write_text("\n".join(moved) + "\n")
    jump = load_session(p).metadata.clock_jump
    assert jump.t == pytest.approx(at, abs=0.05) and "sensor clock" in jump.what
    p.write_text("\n".join(body) + "\n")
    assert load_session(p).metadata.clock_jump is None
    # a sensor clock that drifts away (or is garbage) is no second recording: app time, a warning
    drift = []
    for ln in body:
        f = ln.split(";")
        if f[0] in ("ACCE", "GYRO", "MAGN", "PRES"):
            f[2] = f"{float(f[2]) * 1.5:.4f}"
        drift.append(";".join(f))
    p.write_text("\n".join(drift) + "\n")
    s = load_session(p)
    assert s.metadata.clock_jump is None
    assert any("inconsistent sensor clock" in w for w in s.metadata.warnings)


def test_two_museum_logfiles_joined_with_no_pause(tmp_path):
    """Two real IPIN walks, the second's app clock moved to follow the first by 10 ms, its
    sensor clock as recorded: quarantined where it begins."""
    a, b = (need(IPIN / "logfiles" / f"IPIN2023_T3_TrainingTrial{n}.txt")
            for n in ("01_repetition01", "03_repetition01"))  # fmt: skip
    la, lb = (x.read_text(encoding="utf-8", errors="replace").splitlines() for x in (a, b))

    def app(ln: str) -> float | None:
        f = ln.split(";")
        try:
            return float(f[1]) if len(f) > 2 and f[0].isupper() else None
        except ValueError:
            return None

    ta = max(t for t in map(app, la) if t is not None)
    tb = min(t for t in map(app, lb) if t is not None)
    out = list(la)
    for ln in lb:
        t = app(ln)
        if t is not None:
            f = ln.split(";")
            f[1] = f"{t + ta + 0.01 - tb:.3f}"
            out.append(";".join(f))
    p = tmp_path / "joined.txt"
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    jump = load_session(p).metadata.clock_jump
    assert jump.t == pytest.approx(ta + 0.01, abs=0.1)


def test_a_session_folder_with_a_malformed_clock_jump_is_refused(tmp_path, capsys):
    s = load_session(sorted(MSILC.glob("*.txt.gz"))[0])
    write_session(s, tmp_path / "w")
    header = tmp_path / "w" / "session.yaml"
    h = yaml.safe_load(header.read_text())
    h["metadata"]["clock_jump"] = {"t": "soon", "what": "x"}
    header.write_text(yaml.safe_dump(h))
    assert main(["info", str(tmp_path / "w")]) == 2
    err = capsys.readouterr().err
    assert "session.yaml" in err and "clock_jump" in err and "Traceback" not in err
