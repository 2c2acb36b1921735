"""Never a wrong walk in the map: a walk the pipeline is unsure of writes its result, but is
quarantined — said first, exit status 3, marked in radiomap.csv and summary.json, refused by
merge and localize unless asked, kept out of campaign maps."""

import json

import pytest

from tests.conftest import REPO
from workstation.cli import main
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


def test_a_walk_that_matched_nothing_is_quarantined(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["run", str(MS), "--graph", str(_far_graph(tmp_path)), "--start", "A",
                 "--out", str(out), "--force"])  # fmt: skip
    assert code == EXIT_QUARANTINED
    printed = capsys.readouterr().out
    # said before the results, with the reason and what to do
    assert printed.index("quarantined") < printed.index("wrote")
    assert "no landmark matched" in printed and "workstation edit" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["quarantined"] is True
    assert "nothing_matched" in {q["reason"] for q in summary["quarantine"]}
    assert "# quarantined: " in (out / "radiomap.csv").read_text().split("\n", 2)[0] + "\n"


def test_merge_and_localize_refuse_a_quarantined_map_unless_asked(tmp_path, capsys):
    held = tmp_path / "held"
    main(["run", str(MS), "--graph", str(_far_graph(tmp_path)), "--start", "A",
          "--out", str(held), "--force"])  # fmt: skip
    good = tmp_path / "good"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"),
                 "--out", str(good)]) == 0  # fmt: skip
    capsys.readouterr()
    maps = [str(good / "radiomap.csv"), str(held / "radiomap.csv")]
    assert main(["merge", *maps, "-o", str(tmp_path / "m.csv")]) == 2
    err = capsys.readouterr().err
    assert "quarantined" in err and "held" in err and "--include-quarantined" in err
    assert not (tmp_path / "m.csv").exists()
    assert main(["merge", *maps, "-o", str(tmp_path / "m.csv"), "--include-quarantined"]) == 0
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
        ({"landmarks_matched": 3, "reference_points": 5}, set()),
        ({"landmarks_matched": 3, "reference_points": 5, "start_ambiguous": True,
          "start_node": "L1", "start_alternative": "L2", "start_margin": 0.4},
         {"start_ambiguous"}),
        ({"landmarks_matched": 0, "reference_points": 5, "steps": 40, "landmarks_detected": 0},
         {"nothing_matched"}),
        ({"landmarks_matched": 2, "reference_points": 0, "scans": 12}, {"no_reference_point"}),
    ],
)  # fmt: skip
def test_reasons(summary, reasons):
    got = quarantine(summary)
    assert {q.reason for q in got} == reasons
    assert all(q.remedy for q in got)


def test_no_detections_says_what_was_missing():
    (q,) = quarantine({"landmarks_matched": 0, "reference_points": 3, "steps": 40,
                       "landmarks_detected": 0})  # fmt: skip
    assert "no turn, stop or floor change was detected" in q.detail


def test_a_full_disk_names_the_file_being_written(tmp_path, monkeypatch, capsys):
    import errno
    import os as _os

    from workstation import _atomic

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
    assert not list(out.glob(".*.tmp"))  # no half-written file left behind
