"""The campaign's passes that run walks again, on the ten bundled mall walks: with the map of
the building's other walks (and a stop half-way through it), a walk the others keep out, a walk
whose input could not be read (split from test_campaign_starts.py)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from tests.test_campaign_starts import _mall_campaign
from workstation.campaign import run_campaign
from workstation.graph import LandmarkGraph


def test_each_walk_runs_again_with_the_map_of_the_others(tmp_path, monkeypatch):
    """The ten mall walks started at their first tap: each runs again with the first runs'
    maps of the other walks (quarantined ones have none) weighing in on its chain of matches;
    nothing changed, nothing runs; one walk's new start runs it again and, its first map being
    new, every other walk again with the map."""
    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, truth, _ = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()
    out = tmp_path / "out"
    rep = run_campaign(root, out, workers=1, say=lambda s: None)
    assert rep.run_now == 10 and rep.run_again_with_map == 10
    for w in rep.per_walk:
        assert w.summary.chain_by_map is not None and w.summary.chain_by_map.chains >= 1
    held = [w.key for w in rep.per_walk if w.quarantined]
    kept = [w.key for w in rep.per_walk if not w.quarantined]
    assert kept and all((out / "walks" / k / "first.parquet").is_file() for k in kept)
    assert not any((out / "walks" / k / "first.parquet").is_file() for k in held)
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 0 and again.run_again_with_map == 0
    name = sorted(truth)[0]
    other = next(n for n in LandmarkGraph.load(b / "graph.yaml").ids if n != truth[name])
    (b / "starts.yaml").write_text(f"{name}: {other}\n")
    third = run_campaign(root, out, workers=1, say=lambda s: None)
    assert third.run_now == 1 and third.run_again_with_map >= 9


def test_a_map_pass_stopped_half_way_keeps_the_walks_it_ran(tmp_path, monkeypatch):
    """Issue #66: ``state.json`` was written only once the map pass was over, so a kill in the
    map pass of a big campaign lost every walk it had run again. Stopped (Ctrl+C) after the
    pass stored two of its walks: state.json lists them, and the next run runs only the rest."""
    import workstation.campaign.run as campaign

    monkeypatch.setitem(sys.modules, "distributed", None)
    monkeypatch.setattr(campaign, "STATE_EVERY_S", 0.0)  # every result committed: deterministic
    root, b, _, walks = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()
    out, stored = tmp_path / "out", []
    store = campaign._store

    def stop_in_the_map_pass(o, res):
        if len(stored) == len(walks) + 2:  # the first pass's walks, then two of the map pass
            raise KeyboardInterrupt
        stored.append(res.key)
        return store(o, res)

    monkeypatch.setattr(campaign, "_store", stop_in_the_map_pass)
    with pytest.raises(KeyboardInterrupt):
        run_campaign(root, out, workers=1, say=lambda s: None)
    state = json.loads((out / "state.json").read_text())
    assert sorted(k for k in state if k.endswith("@map")) == sorted(
        k + "@map" for k in stored[len(walks):])
    monkeypatch.setattr(campaign, "_store", store)
    rep = run_campaign(root, out, workers=1, say=lambda s: None)
    assert rep.run_now == 0 and rep.run_again_with_map == len(walks) - 2


def test_a_walk_given_a_wrong_start_is_kept_out_by_the_other_walks(tmp_path, monkeypatch):
    """A surveyor's slip: one walk given a start 20 m from where it began (starts.yaml). Its
    own run cannot tell (the start is the surveyor's word), but the building's other walks can:
    its points lie where their WiFi does not put them — it is kept out of the merged map and
    listed under "Needs the surveyor" with the distance and what to do (walks/joint.py); the
    walks near where it was put are not condemned with it. Fixed, every walk is back."""
    import pandas as pd

    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, truth, _ = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()  # every walk from its first tap
    name = "5dd9e7c1c5b77e0006b17333"
    (b / "starts.yaml").write_text(f"{name}: L144\n")  # 20 m from its first tap's landmark
    assert truth[name] != "L144"
    out = tmp_path / "out"
    rep = run_campaign(root, out, workers=1, say=lambda s: None)
    w = {w.key: w for w in rep.per_walk}[f"mall/{name}"]
    assert [q.reason for q in w.quarantine] == ["unreconciled"]
    assert w.joint.disagree_m >= 10 and w.joint.left_out
    held = {w.key: w for w in rep.per_walk if w.quarantined}
    assert set(held) == {f"mall/{name}"}
    md = (out / "campaign.md").read_text().split("## Needs the surveyor")[1]
    assert f"| mall/{name} |" in md and "the other walks' WiFi still puts it" in md
    merged = pd.read_parquet(out / "radiomap")
    per = {w.key: w.summary.reference_points for w in rep.per_walk}
    assert rep.buildings["mall"].reference_points == len(merged)
    from workstation.campaign.jobs import load_map

    # the other walks' points and their rows on standby whose σ lets them join (standby.py),
    # none of the one out
    maps = {k: load_map(out / "walks" / k / "map.parquet") for k in per if k not in held}
    points = sum(int((~m.on_standby).sum()) for m in maps.values())
    assert points < len(merged) <= sum(len(m) for m in maps.values())
    (b / "starts.yaml").write_text(f"{name}: {truth[name]}\n")  # the slip fixed
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert not [w.key for w in again.per_walk if w.quarantined]


def test_a_walk_whose_input_could_not_be_read_runs_again_next_time(tmp_path, monkeypatch):
    """Issue #67 item 3: a walk that failed because its input could not be read (here: gone
    from the disk, as objects of a bucket deleted mid-campaign) is not remembered as done — the
    next run tries it again and it runs; a walk that failed for what its file holds stays failed
    until the file changes."""
    from workstation.campaign import execute, jobs

    monkeypatch.setitem(sys.modules, "distributed", None)
    # the walks run in this process (the pool's would not see the patch below)
    monkeypatch.setattr(execute.Executor, "_pool", lambda self, todo: map(jobs.run_walk, todo))
    root, b, _, walks = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()
    gone, broken = sorted(b.glob("walks/*.gz"))[:2]
    kept = gone.read_bytes()
    real = jobs.load_session

    def vanishing(path):  # the object disappears between the listing and the read
        if Path(path).name == gone.name:
            gone.unlink()
        return real(path)

    monkeypatch.setattr(jobs, "load_session", vanishing)
    broken.write_bytes(b"\x1f\x8b not a gzip at all")
    out = tmp_path / "out"
    said: list[str] = []
    rep = run_campaign(root, out, workers=1, say=said.append)
    failed = {w.key for w in rep.per_walk if w.status == "failed"}
    key = lambda p: f"mall/{p.name.split('.')[0]}"  # noqa: E731
    assert {key(gone), key(broken)} <= failed
    assert any("tried again on the next run" in s and key(gone) in s for s in said), said
    monkeypatch.setattr(jobs, "load_session", real)
    gone.write_bytes(kept)  # restored, the same bytes
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 1  # the restored walk; the broken one stays failed, unchanged
    by = {w.key: w for w in again.per_walk}
    assert by[key(gone)].status != "failed" and by[key(broken)].status == "failed"
