"""Outputs at a store's URL (issue #64 item 1): `run --out s3://…`, `merge -o s3://…` and
`quality --out s3://…` printed "wrote s3:/…" and wrote a local folder named ``s3:``. They now
write to the store (the same bytes a local output gets; an object already there kept as
``.bak``); every other command's output refuses a URL in one line, exit 2, writing nothing."""

from __future__ import annotations

import os

import pytest

from tests.conftest import REPO
from tests.s3 import local_s3, need_store
from workstation.cli import main

need_store()

MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"
OFFICE = REPO / "sample_sessions" / "office2f" / "normal"


@pytest.fixture(scope="module")
def s3():
    import fsspec

    with local_s3():
        fs = fsspec.filesystem("s3")
        fs.mkdir("survey")
        yield fs


@pytest.fixture
def here(tmp_path, monkeypatch):
    """The working folder: nothing may appear in it (a folder named ``s3:`` did)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _run_both(here, s3, capsys, url: str):
    local = here / "local_run"
    assert main(["run", str(MS), "--graph", str(MS / "graph.yaml"), "--out", str(local)]) == 0
    capsys.readouterr()
    assert main(["run", str(MS), "--graph", str(MS / "graph.yaml"), "--out", url]) == 0
    return local, capsys.readouterr().out


def test_run_writes_its_folder_to_the_store(s3, here, capsys):
    url = "s3://survey/single"
    local, said = _run_both(here, s3, capsys, url)
    assert f"wrote {url}/" in said
    for f in ("radiomap.csv", "trajectory.csv", "landmarks.csv", "segments.csv", "summary.json"):
        assert s3.cat(f"survey/single/{f}") == (local / f).read_bytes(), f
    assert sorted(os.listdir(here)) == ["local_run"]  # no ./s3:/ folder
    # again: the objects there are kept as .bak first
    assert main(["run", str(MS), "--graph", str(MS / "graph.yaml"), "--out", url]) == 0
    assert s3.exists("survey/single/radiomap.csv.bak")


def test_merge_and_quality_write_to_the_store(s3, here, capsys):
    run = here / "r"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out", str(run)]) == 0
    m = str(run / "radiomap.csv")
    assert main(["merge", m, "-o", str(here / "m.csv")]) == 0
    capsys.readouterr()
    assert main(["merge", m, "-o", "s3://survey/maps/merged.csv"]) == 0
    assert "wrote s3://survey/maps/merged.csv:" in capsys.readouterr().out
    assert s3.cat("survey/maps/merged.csv") == (here / "m.csv").read_bytes()
    assert main(["quality", "--map", m, "--out", "s3://survey/quality", "--aps", "1"]) == 0
    assert "wrote s3://survey/quality/quality.json" in capsys.readouterr().out
    names = {p.rsplit("/", 1)[-1] for p in s3.ls("survey/quality")}
    assert "quality.json" in names and any(n.endswith(".png") for n in names)
    assert sorted(os.listdir(here)) == ["m.csv", "r"]


@pytest.mark.parametrize("argv", [
    ["graph", "from-tra", "x.tra", "-o", "s3://survey/g.yaml"],
    ["graph", "from-waypoints", "w.txt", "-o", "s3://survey/g.yaml"],
    ["building", "from-msilc", "f.json", "-o", "s3://survey/b.yaml"],
    ["evaluate", "--walks", "a", "--graph", "g.yaml", "--out", "s3://survey/e"],
    ["simulate", "--building", "office2f", "--walk", "normal", "--out", "s3://survey/s"],
    ["split", "w.txt", "--out", "s3://survey/parts"],
    ["layouts", "--out", "s3://survey/layouts"],
    ["view", str(MS), "--graph", "g.yaml", "--save", "s3://survey/v.rrd"],
    ["merge", "a.csv", "-o", "m.csv", "--save", "s3://survey/j.rrd"],
    ["demo", "--out", "s3://survey/demo"],
    ["plan", "--graph", "g.yaml", "--out", "s3://survey/plan"],
    ["edit", str(MS), "--graph", "g.yaml", "--out", "s3://survey/o"],
    ["edit", str(MS), "--graph", "g.yaml", "--save", "s3://survey/e.rrd"],
    ["building", "from-ipin-cal", "x.cal", "-o", "s3://survey/b.yaml"],
    ["building", "from-points", "p.png", "--point", "1,1=0,0", "-o", "s3://survey/b.yaml"],
])  # fmt: skip
def test_every_other_output_refuses_a_url_in_one_line(argv, here, capsys):
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "this output is written only on this machine" in err
    assert os.listdir(here) == []
