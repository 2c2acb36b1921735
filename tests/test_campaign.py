"""Campaigns (issue #16): two buildings run on a 2-worker Dask LocalCluster — a broken walk is
reported and the others complete; a second run re-processes nothing; a changed graph
re-processes only its building; without Dask a local process pool does the same."""

import json
import re
import shutil
import sys

import pytest

from tests.conftest import IPIN, REPO
from workstation.campaign import run_campaign
from workstation.campaign.outcome import CampaignReport
from workstation.campaign.report_md import _ends_on
from workstation.campaign.walk_row import WalkRow

OFFICE = REPO / "sample_sessions" / "office2f"
MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"


def _campaign(tmp_path):
    root = tmp_path / "campaign"
    office = root / "buildings" / "office"
    (office / "walks").mkdir(parents=True)
    shutil.copy(OFFICE / "normal" / "graph.yaml", office / "graph.yaml")
    for w in ("normal", "varied", "heldout"):
        shutil.copytree(OFFICE / w, office / "walks" / w)
    (office / "walks" / "broken.txt").write_text("not a walk\n")
    mall = root / "buildings" / "mall"
    (mall / "walks").mkdir(parents=True)
    shutil.copy(MS / "graph.yaml", mall / "graph.yaml")
    shutil.copytree(MS, mall / "walks" / "ms")
    return root


def test_campaign_on_a_local_dask_cluster(tmp_path):
    pytest.importorskip("distributed")
    root, out = _campaign(tmp_path), tmp_path / "out"
    lines = []
    rep = run_campaign(root, out, workers=2, say=lines.append)
    assert any("LocalCluster, 2 workers" in ln and "127.0.0.1" in ln for ln in lines)
    # one cluster for the whole run, its passes included (issue #50 item 9: three dashboards)
    assert rep.run_again_with_map > 0 and sum("LocalCluster" in ln for ln in lines) == 1, lines
    by = {w.key: w for w in rep.per_walk}
    assert (
        by["office/broken"].status == "failed"
        and "unrecognised format" in by["office/broken"].error
    )
    assert all(
        by[k].status == "ok"
        for k in ("office/normal", "office/varied", "office/heldout", "mall/ms")
    )
    office = rep.buildings["office"]
    assert office.reference_points > 200 and office.leave_one_out["mean_m"] < 5.0
    assert (out / "radiomap" / "building=office" / "floor=1.0").is_dir() or (
        out / "radiomap" / "building=office" / "floor=1"
    ).is_dir()
    saved = json.loads((out / "campaign.json").read_text())  # the report reads back as written
    assert CampaignReport.from_json(saved).to_json() == saved
    assert CampaignReport.from_json(saved).buildings["office"] == office
    md = (out / "campaign.md").read_text()
    assert "broken" in md and "| ends on |" in md
    # a walk that ran is not "ok" when it needs the surveyor (issue #64 item 7): the building
    # table says ran, in the map and needing the surveyor apart
    assert "| building | walks | ran | in the map | need the surveyor |" in md
    row = next(ln for ln in md.splitlines() if ln.startswith("| office |")).split("|")
    walks, ran, in_map, held = (int(c) for c in row[2:6])
    assert (walks, ran) == (office.walks, office.walks_ok) and in_map + held == ran
    assert held == office.walks_quarantined
    ms = next(ln for ln in md.splitlines() if ln.startswith("| mall/ms |"))
    assert _ends_on(by["mall/ms"]) in ms and by["mall/ms"].summary.end.how
    # a second run re-processes nothing
    rep2 = run_campaign(root, out, workers=2, say=lines.append)
    assert rep2.run_now == 0 and rep2.walks_ok == 4
    # a changed graph re-processes only that building
    g = root / "buildings" / "mall" / "graph.yaml"
    g.write_text(g.read_text() + "\n# edited\n")
    rep3 = run_campaign(root, out, workers=2, say=lines.append)
    assert rep3.run_now == 1
    assert (
        json.loads((out / "walks" / "mall" / "ms" / "summary.json").read_text())["status"] == "ok"
    )


def test_ctrl_c_stops_a_campaign_without_a_traceback(tmp_path):
    """Issue #50 item 9: Ctrl+C in a terminal (SIGINT to the whole process group) printed each
    Dask worker's KeyboardInterrupt traceback. Once a walk is stored: exit 130, one line saying
    what was kept, no traceback; the next run finishes the rest."""
    import os
    import signal
    import subprocess
    import time

    pytest.importorskip("distributed")
    root, out = _campaign(tmp_path), tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "workstation", "campaign", "run", str(root), "--out", str(out),
         "--workers", "2"],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,  # its own group, as a terminal gives it; Ctrl+C as it sends it:
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # (not inherited off)
    )  # fmt: skip
    state = out / "state.json"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if state.is_file() and len(json.loads(state.read_text() or "{}")) >= 1:
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert "interrupted" in err.splitlines()[-1]
    said: list[str] = []
    rep = run_campaign(root, out, workers=2, say=said.append)
    # what state.json listed is not run again (the passes that run walks again may still pick
    # it, depending on which walk was stored first: run_now is no measure of that)
    assert rep.walks_ok == 4
    kept = re.search(r"(\d+) to run, (\d+) unchanged", said[0])
    assert kept is not None and int(kept[2]) >= 1 and int(kept[1]) < 5, said[0]


def test_campaign_without_dask_uses_a_process_pool(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails as if not installed
    root, out = _campaign(tmp_path), tmp_path / "out"
    lines = []
    rep = run_campaign(root, out, workers=2, say=lines.append)
    assert any("Dask is not installed" in ln for ln in lines)
    assert rep.walks_ok == 4 and rep.walks == 5


def test_a_campaign_builds_the_kind_of_map_asked_for(tmp_path, monkeypatch):
    """``kind``: each building's radiomap/ is that kind (fingerprints/kinds.py), said in its
    metadata and read back by localize's reader; run again with points, the map is points."""
    import numpy as np

    from workstation.fingerprints.localize import Fingerprints

    monkeypatch.setitem(sys.modules, "distributed", None)
    root, out = _campaign(tmp_path), tmp_path / "out"
    run_campaign(root, out, workers=2, say=lambda _: None, kind="interpolated")
    built = Fingerprints.read(out / "radiomap" / "building=office")
    assert built.kind == "interpolated"
    rep = run_campaign(root, out, workers=2, say=lambda _: None)
    points = Fingerprints.read(out / "radiomap" / "building=office")
    assert points.kind == "points" and rep.buildings["office"].reference_points == len(points)
    # the virtual points lie where the walks' points are, more of them
    from workstation.fingerprints.kind_interpolated import NEAR_M

    d = np.hypot(built.x[:, None] - points.x[None], built.y[:, None] - points.y[None])
    d = np.where(built.floor[:, None] == points.floor[None], d, np.inf).min(axis=1)
    assert d.max() <= NEAR_M + 1e-6 and len(built) > len(points)


@pytest.mark.shared_data
def test_museum_campaign_from_a_yaml_listing(tmp_path):
    pytest.importorskip("distributed")
    from tests.conftest import need
    from workstation.graph.importers import graph_from_tra

    logs = need(IPIN / "logfiles")
    g = graph_from_tra(sorted((IPIN / "supplementary" / "trajectories").glob("*.tra")))
    g.save(tmp_path / "museum.yaml")
    office = OFFICE / "normal"
    (tmp_path / "campaign.yaml").write_text(
        f"buildings:\n  museum: {{graph: museum.yaml, walks: ['{logs}/*.txt']}}\n"
        f"  office: {{graph: '{office}/graph.yaml', walks: ['{office}', '{OFFICE}/heldout']}}\n"
    )
    rep = run_campaign(tmp_path / "campaign.yaml", tmp_path / "out", workers=2, say=lambda s: None)
    m = rep.buildings["museum"]
    assert m.walks_ok == 10 and m.reference_points > 300
    assert m.leave_one_out["floor_accuracy"] > 0.7
    assert rep.buildings["office"].walks_ok == 2


def test_a_killed_campaign_resumes_where_it_stopped(tmp_path):
    """SIGKILL the whole `campaign run` (CLI, Dask or pool) once the first walk is stored: the
    files written so far are whole, and the next run runs only the walks not yet stored."""
    import os
    import signal
    import subprocess
    import time

    root, out = _campaign(tmp_path), tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "workstation", "campaign", "run", str(root), "--out", str(out),
         "--workers", "1"],
        cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
    )  # fmt: skip
    state = out / "state.json"
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if state.is_file() and len(json.loads(state.read_text() or "{}")) >= 1:
                break
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    done = json.loads(state.read_text())  # whole JSON: written atomically
    assert 1 <= len(done) < 5, "the run was not stopped half-way"
    for key in done:
        json.loads((out / "walks" / key / "summary.json").read_text())
    litter = out / "walks" / next(iter(done)) / ".summary.json.a1b2c3d4.tmp"  # as a kill leaves
    litter.write_text("{")
    said = []
    rep = run_campaign(root, out, workers=1, say=said.append)
    assert rep.run_now == 5 - len(done)
    assert rep.walks_ok == 4 and rep.walks == 5
    assert not litter.exists() and any("temporary file(s) a killed run" in s for s in said)
    assert not list(out.rglob("*.tmp"))


@pytest.mark.shared_data
def test_walks_that_stood_together_decide_their_start_in_a_campaign(tmp_path, monkeypatch):
    """Museum, starts inferred: Trial21 rep01 alone takes L22 (ambiguous); with rep03, which
    stood at the same place, the campaign runs it again from L31 (the truth). A second run
    runs nothing, and the report says who decided the start with whom."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # the process pool: quicker here
    from tests.conftest import need
    from workstation.graph.importers import graph_from_tra

    logs = need(IPIN / "logfiles")
    g = graph_from_tra(sorted((IPIN / "supplementary" / "trajectories").glob("*.tra")))
    g.save(tmp_path / "museum.yaml")
    walks = [f"{logs}/IPIN2023_T3_TrainingTrial{n}.txt"
             for n in ("21_repetition01", "21_repetition03", "04_repetition01")]  # fmt: skip
    (tmp_path / "campaign.yaml").write_text(
        f"buildings:\n  museum: {{graph: museum.yaml, walks: {walks}, start: infer}}\n"
    )
    out, lines = tmp_path / "out", []
    rep = run_campaign(tmp_path / "campaign.yaml", out, workers=2, say=lines.append)
    starts = {w.key.split("Trial")[1]: w for w in rep.per_walk}
    assert starts["21_repetition01"].summary.start_node == "L31"
    assert starts["21_repetition01"].start_shared_with == (
        "museum/IPIN2023_T3_TrainingTrial21_repetition03",
    )
    assert starts["21_repetition03"].summary.start_node == "L31"
    assert starts["04_repetition01"].summary.start_node == "L18"
    assert any("L22 → L31" in ln for ln in lines), lines
    assert "decided with" in (out / "campaign.md").read_text()
    again = run_campaign(tmp_path / "campaign.yaml", out, workers=2, say=lines.append)
    assert again.run_now == 0
    assert {w.key: w.summary.start_node for w in again.per_walk} == {
        w.key: w.summary.start_node for w in rep.per_walk
    }


def test_shared_start_pass_is_incremental(tmp_path):
    """The campaign's shared-start pass on stored summaries (no data needed): walks a and b
    stood at one place (same stand fingerprint), a is ambiguous and prefers C, b prefers B:
    a is run again from B; the next pass runs nothing; once their stands differ, a is run
    again on its own."""
    from pathlib import Path

    from workstation.campaign.jobs import WalkJob
    from workstation.campaign.layout import BuildingSpec
    from workstation.campaign.records import Records
    from workstation.campaign.shared_pass import shared_starts
    from workstation.campaign.walk_result import WalkResult

    aps = [f"ap{i}" for i in range(6)]
    here, there = [-40.0, -50, -60, -85, -85, -85], [-85.0, -85, -85, -40, -50, -60]

    def stored(key, cands, stand, extra=None):
        d = tmp_path / "walks" / key
        d.mkdir(parents=True, exist_ok=True)
        meta = {
            "key": key,
            "status": "ok",
            "summary": {"start_node": cands[0][0]},
            "start_inference": {"candidates": cands, "stand": [aps, stand], "tau_dbm": -90.0},
        }
        (d / "summary.json").write_text(json.dumps(meta | (extra or {})))  # fmt: skip

    jobs = [WalkJob("m", Path(f"{k}.txt"), Path("g.yaml"), None, "infer", f"m/{k}", f"d{k}")
            for k in "abc"]  # fmt: skip
    spec = [BuildingSpec("m", Path("g.yaml"), tuple(j.walk for j in jobs), start="infer")]
    stored("m/a", [["C", 0.0], ["B", 0.5]], here)
    stored("m/b", [["B", 0.0], ["C", 2.0]], [v + 0.5 for v in here])
    stored("m/c", [["E", 0.0], ["B", 1.0]], there)

    def execute(todo):
        for j in todo:
            yield WalkResult(j.key, status="ok", digest=j.digest, figures={"start_node": j.start})

    state, said = {}, []

    def again(records):  # a run of the pass, as a campaign run makes it
        def store(res):  # as the campaign keeps a result
            records.write(res)

        return shared_starts(spec, jobs, state, False, said.append, execute, records, store)

    ran = again(Records(tmp_path))
    assert [(j.key, j.start) for j in ran] == [("m/a", "B")]
    meta = json.loads((tmp_path / "walks" / "m" / "a" / "summary.json").read_text())
    assert (
        meta["start_shared"]["with"] == ["m/b"]
        and meta["start_inference"]["candidates"][0][0] == "C"
    )
    assert state["m/a@shared"] == "da|shared:B" and any("C → B" in s for s in said)
    assert again(Records(tmp_path)) == []
    stored("m/b", [["B", 0.0], ["D", 2.0]], there)  # b re-recorded elsewhere: no decision now
    stored("m/c", [["E", 0.0], ["B", 1.0]], [-85.0, -40, -85, -50, -85, -60])
    ran = again(Records(tmp_path))
    assert [(j.key, j.start) for j in ran] == [("m/a", "infer")] and "m/a@shared" not in state


@pytest.mark.parametrize("name", ["../outside", "a/b", "..", "x" * 101, "/abs"])
def test_a_building_name_cannot_leave_the_output_folder(tmp_path, name):
    """Issue #33: a building called '../x' wrote outside --out. Names are one plain folder
    name; anything else is refused naming the file, before anything is written."""
    from workstation.campaign import load_campaign
    from workstation.errors import InputError

    c = tmp_path / "c.yaml"
    c.write_text(
        "buildings:\n"
        f"  {json.dumps(name)}: {{graph: {OFFICE / 'normal' / 'graph.yaml'}, walks: []}}\n"
    )
    with pytest.raises(InputError, match="is not a building name") as e:
        load_campaign(c)
    assert str(c) in str(e.value)


def test_walks_that_would_share_a_key_each_keep_their_own(tmp_path):
    """Issue #33: walk.txt in two folders, or a.txt beside a.csv, got one key and one walk was
    lost. Each walk now has its own folder name, in the order listed; names are made safe."""
    from pathlib import Path

    from workstation.campaign import walk_keys

    walks = [Path("x/walk.txt"), Path("y/walk.txt"), Path("a.txt"), Path("a.csv"),
             Path("b.txt.gz"), Path("we ird$.txt"), Path("..txt")]  # fmt: skip
    keys = walk_keys(walks)
    assert keys[:5] == ["walk", "walk~2", "a", "a~2", "b"]
    assert len(set(keys)) == len(keys)
    assert all("/" not in k and not k.startswith(".") for k in keys)


def test_the_walk_table_says_where_each_walk_ended():
    """ "matched 0" beside "ok" is a walk whose end closed tightly enough to check it: the
    table says where and to within what σ."""

    def ends(**figures):
        return _ends_on(WalkRow("b/w", "b", "ok", figures=figures))

    assert ends(end_how="closed", end_node="L7", end_sigma_m=0.9) == "L7 (σ 0.9 m)"
    assert ends(end_how="ambiguous", end_node=None) == "open"
    assert ends(end_how="far") == "open"
    assert ends(end_how="at_last_match") == "last match"
    assert ends() == "–"
    assert ends(end_how="given", end_node="L9", end_sigma_m=6.0) == "L9 (given)"
    assert "elsewhere" in ends(end_how="given_far", end_node="L9")


@pytest.mark.parametrize("value", ["false", "[]", "{}", "null", "''"])
def test_a_start_that_is_no_start_is_refused_naming_the_file(tmp_path, value):
    """Issue #55 item 7: `start: false` (or [], {}, null, "") silently meant "no start". A start
    is a landmark id, first-fix or infer; 0 is the landmark "0"."""
    from workstation.campaign import load_campaign
    from workstation.errors import InputError

    c = tmp_path / "c.yaml"
    g = OFFICE / "normal" / "graph.yaml"
    c.write_text(f"buildings:\n  office: {{graph: {g}, walks: [], start: {value}}}\n")
    with pytest.raises(InputError, match="buildings.office.start: a landmark id") as e:
        load_campaign(c)
    assert str(c) in str(e.value)
    c.write_text(f"buildings:\n  office: {{graph: {g}, walks: [], start: 0}}\n")
    assert load_campaign(c)[0].start == "0"


def test_planning_survives_a_walk_path_no_file_system_takes(tmp_path):
    """Issue #55 (the extended fuzz probe): a walk named with 1,000 characters raised OSError
    while planning the jobs, and one mistyped as a parent folder hashed every file under it."""
    from pathlib import Path

    from workstation.campaign import walk_keys
    from workstation.campaign.jobs import file_digest

    long = Path("/tmp/" + "x" * 1000)
    assert walk_keys([long]) == ["x" * 100]
    assert file_digest(long) == "unreadable"
    (tmp_path / "deep" / "er").mkdir(parents=True)
    (tmp_path / "deep" / "er" / "big.bin").write_bytes(b"x")
    (tmp_path / "deep" / "a.txt").write_text("a")
    before = file_digest(tmp_path / "deep")
    (tmp_path / "deep" / "er" / "big.bin").write_bytes(b"y")  # below the folder: not a walk's
    assert file_digest(tmp_path / "deep") == before
