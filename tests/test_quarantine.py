"""Never a wrong walk in the map: a walk the pipeline is unsure of writes its result, but is
quarantined — said first, exit status 3, marked in radiomap.csv and summary.json, refused by
merge and localize unless asked, kept out of campaign maps."""

import json

import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.fingerprints.localize import Fingerprints
from workstation.pipeline.summary import Summary
from workstation.pipeline.verdict import EXIT_QUARANTINED, quarantine

MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"
OFFICE = REPO / "sample_sessions" / "office2f" / "normal"


def _far_graph(tmp_path):
    """Two landmarks with rules 300 m from the walk: nothing it does can match them."""
    g = tmp_path / "far.yaml"
    g.write_text(
        "nodes:\n"
        "- {id: A, x: 400.0, y: 400.0, floor: 0, rules: [gyro]}\n"
        "- {id: B, x: 420.0, y: 400.0, floor: 0, rules: [gyro]}\n"
        "edges:\n- {from: A, to: B}\n"
    )
    return g


def test_a_walk_whose_inferred_start_nothing_checks_is_quarantined(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["run", str(MS), "--graph", str(_far_graph(tmp_path)), "--start", "infer",
                 "--out", str(out), "--force"])  # fmt: skip
    assert code == EXIT_QUARANTINED
    printed = capsys.readouterr().out
    # said before the results, with the reason and what to do
    assert printed.index("quarantined") < printed.index("wrote")
    assert "workstation edit" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["quarantined"] is True
    assert {q["reason"] for q in summary["quarantine"]} & {"nothing_matched", "start_ambiguous"}
    assert "# quarantined: " in (out / "radiomap.csv").read_text().split("\n", 2)[0] + "\n"


def test_a_given_start_that_matched_nothing_far_from_the_graph_is_quarantined(tmp_path):
    """From a given start 300 m from where it was walked, the walk matches nothing and its track
    runs far from every edge: the sensors contradict the start or the graph (off_graph)."""
    out = tmp_path / "run"
    code = main(["run", str(MS), "--graph", str(_far_graph(tmp_path)), "--start", "A",
                 "--out", str(out), "--force"])  # fmt: skip
    assert code == EXIT_QUARANTINED
    summary = json.loads((out / "summary.json").read_text())
    assert [q["reason"] for q in summary["quarantine"]] == ["off_graph"]
    assert (
        summary["off_graph_m"] > 10 and "start or the graph" in summary["quarantine"][0]["detail"]
    )


def test_merge_leaves_a_quarantined_map_out_and_localize_refuses_it_unless_asked(tmp_path, capsys):
    """Issue #64 item 3: merge named the quarantined walks and stopped (exit 2), the surveyor
    filtering by hand. It now leaves them out with their reason and what to do, exit 0, the
    count in its closing line; it refuses only when every map is quarantined."""
    held = tmp_path / "held"
    main(["run", str(MS), "--graph", str(_far_graph(tmp_path)), "--start", "A",
          "--out", str(held), "--force"])  # fmt: skip
    good = tmp_path / "good"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"),
                 "--out", str(good)]) == 0  # fmt: skip
    capsys.readouterr()
    maps = [str(good / "radiomap.csv"), str(held / "radiomap.csv")]
    assert main(["merge", *maps, "-o", str(tmp_path / "m.csv")]) == 0
    said = capsys.readouterr().out
    assert f"warning: {maps[1]}: the walk is quarantined (off_graph): left out" in said
    assert "--include-quarantined merges them anyway" in said and "summary.json" in said
    assert "from 1 maps (1 quarantined left out)" in said
    n = len(Fingerprints.read(tmp_path / "m.csv"))
    assert n == len(Fingerprints.read(maps[0]).settled())
    assert main(["merge", maps[1], "-o", str(tmp_path / "h.csv")]) == 2
    err = capsys.readouterr().err
    assert "every map's walk is quarantined" in err and "--include-quarantined" in err
    assert not (tmp_path / "h.csv").exists()
    assert main(["merge", *maps, "-o", str(tmp_path / "m.csv"), "--include-quarantined"]) == 0
    assert "included as asked" in capsys.readouterr().out
    assert len(Fingerprints.read(tmp_path / "m.csv")) > n
    assert main(["localize", "--map", maps[1], "--session", str(OFFICE)]) == 2


def test_a_sure_walk_is_not_quarantined(tmp_path):
    out = tmp_path / "run"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["quarantined"] is False and s["quarantine"] == []
    assert not (out / "radiomap.csv").read_text().startswith("# quarantined")


@pytest.mark.parametrize(
    "summary, reasons",
    [
        ({"landmarks_matched": 3, "reference_points": 5, "steps": 40}, set()),
        ({"landmarks_matched": 3, "reference_points": 5, "steps": 40, "start_ambiguous": True,
          "start_node": "L1", "start_alternative": "L2", "start_margin": 0.4},
         {"start_ambiguous"}),
        ({"landmarks_matched": 0, "reference_points": 5, "steps": 40, "landmarks_detected": 0,
          "start_margin": 9.0}, {"nothing_matched"}),
        # from a given start (no start_margin: nothing was inferred), dead reckoning from a
        # known place: its σ decides its points, not a quarantine (issue #49)
        ({"landmarks_matched": 0, "reference_points": 5, "steps": 40, "landmarks_detected": 0},
         set()),
        ({"landmarks_matched": 2, "reference_points": 0, "scans": 12, "steps": 40},
         {"no_reference_point"}),
        ({"landmarks_matched": 1, "reference_points": 9, "steps": 0}, {"no_walking"}),
        # an end closed on a landmark checks the walk when placed as tightly as a point may be
        ({"landmarks_matched": 0, "reference_points": 5, "steps": 40, "end_node": "L3",
          "end_sigma_m": 2.5, "start_margin": 9.0}, set()),
        ({"landmarks_matched": 0, "reference_points": 5, "steps": 40, "end_node": "L3",
          "end_sigma_m": 3.5, "start_margin": 9.0}, {"nothing_matched"}),
    ],
)  # fmt: skip
def test_reasons(summary, reasons):
    got = quarantine(Summary.from_json(summary))
    assert {q.reason for q in got} == reasons
    assert all(q.what_to_do for q in got)


def test_no_detections_says_what_was_missing():
    (q,) = quarantine(Summary.from_json({"landmarks_matched": 0, "reference_points": 3, "steps": 40,
                       "landmarks_detected": 0, "start_margin": 9.0}))  # fmt: skip
    assert "no turn, stop or floor change was detected" in q.detail
    assert "its end is near no landmark" in q.detail


def test_a_loosely_closed_end_says_how_loosely():
    """An end closed on a landmark, but with σ above verdict.END_CHECK_M, does not check the
    walk, and the detail says where it closed and how loosely."""
    (q,) = quarantine(Summary.from_json({"landmarks_matched": 0, "reference_points": 3, "steps": 40,
                       "landmarks_detected": 0, "end_node": "L196", "end_sigma_m": 7.5,
                       "start_margin": 9.0}))  # fmt: skip
    assert q.reason == "nothing_matched"
    assert "its end closed on L196 only to within σ 7.5 m (a check needs 3 m or less)" in q.detail
    assert not quarantine(Summary.from_json({"landmarks_matched": 0, "reference_points": 3, "steps": 40,
                           "end_node": "L196", "end_sigma_m": 2.5}))  # fmt: skip


def test_a_full_disk_names_the_file_being_written(tmp_path, monkeypatch, capsys):
    import errno
    import os as _os

    from workstation.io import atomic as _atomic

    real = _os.fsync

    def full(fd):
        real(fd)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(_atomic.os, "fsync", full)
    out = tmp_path / "run"
    code = main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "No space left on device" in err
    assert str(out / "trajectory.csv") in err and "while writing" in err
    assert not out.exists()  # no half-written file, nor the empty folder (issue #67 item 4)


def test_a_run_stopped_by_a_full_disk_leaves_the_previous_outputs_whole(tmp_path, monkeypatch):
    """The five outputs appear together or not at all: a disk filling up at the fourth file
    left this run's trajectory.csv and landmarks.csv beside the previous radiomap.csv."""
    import errno

    from workstation.io import atomic as _atomic

    out = tmp_path / "run"
    args = ["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out", str(out)]
    assert main(args) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    real, calls = _atomic.os.fsync, []

    def fills_up(fd):
        calls.append(fd)
        if len(calls) == 4:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(fd)

    monkeypatch.setattr(_atomic.os, "fsync", fills_up)
    other = [*args, "--start", "SW0"]  # another start: other outputs
    assert main(other) == 2
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    monkeypatch.setattr(_atomic.os, "fsync", real)
    main(other)
    after = {p.name: p.read_bytes() for p in out.iterdir()}
    assert all(after[k] != before[k] for k in before if not k.endswith(".bak"))


def test_a_walk_without_steps_is_quarantined_and_run_says_what_the_reader_said(tmp_path, capsys):
    """A phone lying still gave 105 reference points on the start landmark with exit 0; a walk
    without a gyroscope said nothing of it (issue #33)."""
    from dataclasses import replace

    import numpy as np

    from workstation.session import load_session
    from workstation.session.model import Vector3
    from workstation.session.native import write_session

    s = load_session(OFFICE)
    a, g = s.accelerometer, s.gyroscope
    rng = np.random.default_rng(0)
    still = replace(
        s,
        accelerometer=Vector3(a.t, [0, 0, 9.81] + rng.normal(0, 0.02, (len(a.t), 3))),
        gyroscope=Vector3(g.t, rng.normal(0, 0.01, (len(g.t), 3))),
    )
    folder = write_session(still, tmp_path / "still")
    out = tmp_path / "out"
    code = main(["run", str(folder), "--graph", str(OFFICE / "graph.yaml"), "--start", "EL0",
                 "--out", str(out)])  # fmt: skip
    assert code == 3
    summary = json.loads((out / "summary.json").read_text())
    assert "no_walking" in [q["reason"] for q in summary["quarantine"]]
    folder = write_session(replace(s, gyroscope=Vector3.empty()), tmp_path / "nogyro")
    capsys.readouterr()
    main(["run", str(folder), "--graph", str(OFFICE / "graph.yaml"), "--start", "EL0", "--out",
          str(tmp_path / "out2")])  # fmt: skip
    first = capsys.readouterr().out.splitlines()[0]
    assert first.startswith("warning:") and "no gyroscope: no turn can be detected" in first
    summary = json.loads((tmp_path / "out2" / "summary.json").read_text())
    assert any(w.startswith("no gyroscope") for w in summary["input_warnings"])


def test_the_surveyors_end_checks_a_walk_that_matched_nothing(tmp_path, capsys):
    """`run --end`: the bundled mall walk that matched nothing (tests/data/msilc, its first tap's
    landmark as the start) is in the map from its given start, its points held to the open
    stretch's σ (issue #49); given where it ended — its last tap's landmark — it is checked
    (exit 0) and keeps more points; given a landmark it did not end at, it is held for that
    (exit 3); a landmark the graph does not have is bad input (exit 2), named with the nearest
    id."""
    walk = REPO / "tests" / "data" / "msilc" / "5dd9e7b7c5b77e0006b1732f.txt.gz"
    graph = REPO / "tests" / "data" / "msilc" / "site1_f1_graph.yaml"
    args = ["run", str(walk), "--graph", str(graph), "--start", "first-fix"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert a["landmarks_matched"] == 0 and a["quarantine"] == [] and a["off_graph_m"] < 10
    assert main([*args, "--end", "last-fix", "--out", str(tmp_path / "b")]) == 0
    s = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert s["end_how"] == "given" and s["quarantine"] == [] and s["reference_points"] > 0
    assert s["reference_points"] >= a["reference_points"]
    far = "L01" if s["end_node"] != "L01" else "L02"
    assert main([*args, "--end", far, "--out", str(tmp_path / "c")]) == EXIT_QUARANTINED
    s = json.loads((tmp_path / "c" / "summary.json").read_text())
    assert "end_far" in {q["reason"] for q in s["quarantine"]}
    capsys.readouterr()
    assert main([*args, "--end", "L9999", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert "--end L9999: no such landmark" in err and "Traceback" not in err


def test_a_full_disk_names_the_file_of_every_single_write_and_leaves_no_half_png(tmp_path,
                                                                                 monkeypatch):
    """Issue #67 item 4: `merge`, `graph`, `building`, `quality` said "error: a file: No space
    left on device"; `quality` left a 0-byte PNG. A single file written atomically names itself
    when the disk is full; a figure is drawn in memory and written whole, or not at all."""
    import errno

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pytest

    from workstation.io import atomic as _atomic

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(_atomic.os, "fsync", full)
    target = tmp_path / "merged.csv"
    with pytest.raises(OSError) as e:
        _atomic.atomic_write_bytes(target, b"x,y\n")
    assert e.value.filename == str(target) and "while writing" in str(e.value)
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    png = tmp_path / "floor_0_coverage.png"
    with pytest.raises(OSError) as e:
        _atomic.save_figure(fig, png)
    plt.close(fig)
    assert e.value.filename == str(png) and not png.exists()
    assert not list(tmp_path.glob(".*.tmp"))
