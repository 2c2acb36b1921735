"""A surveyor fixes a campaign walk whose inferred start was ambiguous by giving its start
(``starts.yaml`` beside the graph, or ``starts:`` in the campaign file), helped by what the
building's map says of its candidate starts (workstation/campaign/starts.py)."""

from __future__ import annotations

import json
import shlex
import sys

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.campaign import run_campaign
from workstation.errors import InputError
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

MALL = REPO / "tests" / "data" / "msilc"


def _mall_campaign(tmp_path, given: int):
    """The ten bundled mall walks (MIT), starts inferred, the first ``given`` of them given
    their start (the landmark at their first tap) in a folder's starts.yaml."""
    b = tmp_path / "c" / "buildings" / "mall"
    (b / "walks").mkdir(parents=True)
    g = LandmarkGraph.load(MALL / "site1_f1_graph.yaml")
    (b / "graph.yaml").write_text((MALL / "site1_f1_graph.yaml").read_text())
    walks = sorted(MALL.glob("*.gz"))
    truth = {}
    for w in walks:
        (b / "walks" / w.name).write_bytes(w.read_bytes())
        truth[w.name.split(".")[0]] = resolve_start("first-fix", load_session(w), g)
    (b / "params.yaml").write_text("pdr:\n  start_node: null\n")
    return tmp_path / "c", b, truth, walks


def test_a_walk_given_its_start_in_starts_yaml_runs_from_it(tmp_path, monkeypatch):
    """In a folder campaign whose walks start at their first tap (the default), a starts.yaml
    entry moves one walk's start: that walk alone is run again, from the landmark given."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # the process pool: quicker here
    root, b, truth, _ = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()
    out = tmp_path / "out"
    rep = run_campaign(root, out, workers=1, say=lambda s: None)
    by = {w.key: w for w in rep.per_walk}
    name = sorted(truth)[3]
    assert by[f"mall/{name}"].summary.start_node == truth[name]
    other = next(n for n in LandmarkGraph.load(b / "graph.yaml").ids if n != truth[name])
    (b / "starts.yaml").write_text(f"{name}: {other}\n")
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 1
    assert {w.key: w.summary.start_node for w in again.per_walk}[f"mall/{name}"] == other


@pytest.mark.parametrize(
    "file, text, said",
    [
        ("starts", "no_such_walk: L10\n", "'no_such_walk' is no walk of building mall"),
        ("starts", "5dd9e7aac5b77e0006b1732c: L10\n", "did you mean '5dd9e7aac5b77e0006b1732b'"),
        ("starts", "5dd9e7aac5b77e0006b1732b: L1000\n", "'L1000' is no landmark of"),
        ("starts", "- 5dd9e7aac5b77e0006b1732b\n", "walk starts are a mapping"),
        ("ends", "no_such_walk: L10\n", "ends: 'no_such_walk' is no walk of building mall"),
        ("ends", "5dd9e7aac5b77e0006b1732b: L1000\n", "'L1000' is no landmark of"),
        ("ends", "- 5dd9e7aac5b77e0006b1732b\n", "walk ends are a mapping"),
    ],
)
def test_a_bad_starts_or_ends_file_is_refused_naming_it(tmp_path, file, text, said):
    root, b, _, _ = _mall_campaign(tmp_path, 0)
    (b / f"{file}.yaml").write_text(text)
    with pytest.raises(InputError) as e:
        run_campaign(root, tmp_path / "out", workers=1, say=lambda s: None)
    assert str(b / f"{file}.yaml") in str(e.value) and said in str(e.value)
    assert not (tmp_path / "out" / "walks").exists()  # refused before anything ran


def test_a_walk_that_matched_nothing_is_fixed_by_its_end_in_ends_yaml(tmp_path, monkeypatch):
    """The campaign walk that matched nothing, given its start (the first tap, the default), is
    in the map (issue #49); given an end in ends.yaml its sensors disagree with, it is held for
    that and listed with where its end goes; given its real end (the landmark at its last tap),
    that walk alone runs again and joins the map."""
    from workstation.pipeline.start import resolve_end

    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, _, walks = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()  # starts at the first tap (the default)
    out = tmp_path / "out"
    name = "5dd9e7b7c5b77e0006b1732f"
    first = run_campaign(root, out, workers=1, say=lambda s: None)
    w = {w.key: w for w in first.per_walk}[f"mall/{name}"]
    assert w.summary.landmarks_matched == 0 and not w.quarantined
    g = LandmarkGraph.load(b / "graph.yaml")
    s = load_session(b / "walks" / f"{name}.txt.gz")
    end = resolve_end("last-fix", s, g)
    far = max(g.nodes, key=lambda n: np.hypot(n.x - g.node(end).x, n.y - g.node(end).y)).id
    (b / "ends.yaml").write_text(f"{name}: {far}\n")
    said = []
    rep = run_campaign(root, out, workers=1, say=lambda s: None,
                       progress=lambda i, n, text, phase="": said.append(text))  # fmt: skip
    held = {w.key: w for w in rep.per_walk if w.quarantined}
    assert f"mall/{name}" in held
    assert [q.reason for q in held[f"mall/{name}"].quarantine] == ["end_far"]
    # its progress says so, not "ok" (issue #64 item 7)
    assert f"mall/{name}: quarantined (end_far)" in said and f"mall/{name}: ok" not in said
    md = (out / "campaign.md").read_text()
    assert f"{b / 'ends.yaml'} ({name}: LANDMARK)" in md
    # listed by what fixing each adds: its scans with no point of the merged map within 5 m
    import pandas as pd

    from workstation.campaign.jobs import load_map

    merged = pd.read_parquet(out / "radiomap")
    m = load_map(out / "walks" / "mall" / name / "map.parquet")
    d = np.hypot(
        m.x[:, None] - merged["x"].to_numpy()[None], m.y[:, None] - merged["y"].to_numpy()[None]
    )
    assert held[f"mall/{name}"].map_lacks == int((d.min(axis=1) > 5.0).sum())
    # a walk's map.parquet says its phone model as a merged map does (issue #64 item 7: merge
    # of two of them removed "offsets" between walks of one phone); merging them removes none
    from workstation.cli import main as cli
    from workstation.fingerprints.localize import Fingerprints

    walk_maps = sorted((out / "walks" / "mall").glob("*/map.parquet"))
    assert Fingerprints.read(walk_maps[0]).device == s.metadata.device
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert cli(["merge", *map(str, walk_maps[:3]), "-o", str(tmp_path / "m.csv")]) == 0
    said = buf.getvalue()
    assert "dB removed" not in said and f"one phone model ({s.metadata.device})" in said
    listed = md.split("## Needs the surveyor")[1]
    order = sorted(held, key=lambda k: listed.index(f"| {k} |"))
    assert [held[k].map_lacks for k in order] == sorted(
        (held[k].map_lacks for k in held), reverse=True
    )
    (b / "ends.yaml").write_text(f"{name}: {end}\n")
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 1
    w = {w.key: w for w in again.per_walk}[f"mall/{name}"]
    assert not w.quarantined and w.summary.end.how == "given" and w.summary.end.node == end
    assert again.walks_quarantined == rep.walks_quarantined - 1


def test_the_report_ranks_an_ambiguous_walks_starts_by_the_map(tmp_path, monkeypatch):
    """Starts inferred (campaign file), eight walks given theirs: those are in the map; the two
    left are ambiguous and listed under "Needs the surveyor" with where to give the start and
    their candidate starts ranked by the building's map."""
    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, truth, walks = _mall_campaign(tmp_path, 0)
    names = sorted(truth)
    given = {n: truth[n] for n in names[:8]}
    starts = ", ".join(f"'{n}': {v}" for n, v in given.items())
    listing = [str(b / "walks" / w.name) for w in walks]
    (tmp_path / "c.yaml").write_text(
        f"buildings:\n  mall: {{graph: {b / 'graph.yaml'}, walks: {listing}, start: infer, "
        f"starts: {{{starts}}}}}\n"
    )
    out = tmp_path / "out"
    rep = run_campaign(tmp_path / "c.yaml", out, workers=1, say=lambda s: None)
    by = {w.key.split("/")[1]: w for w in rep.per_walk}
    for n, v in given.items():
        assert by[n].summary.start_node == v
        assert not any(q.reason == "start_ambiguous" for q in by[n].quarantine)
    ambiguous = [by[n] for n in names[8:]
                 if any(q.reason == "start_ambiguous" for q in by[n].quarantine)]  # fmt: skip
    assert ambiguous
    md = (out / "campaign.md").read_text()
    for w in ambiguous:
        ranked = w.start_by_map.ranked
        # its own candidates, and those of the wider search (start_by_map.WIDE_CANDIDATES)
        assert set(w.candidates) <= {c[0] for c in ranked}
        assert len(ranked) > len(w.candidates)
        # likeliest first; each with the median distance the surveyor reads
        ll = [c[2] for c in ranked]
        assert ll == sorted(ll, reverse=True) and all(np.isfinite([c[1] for c in ranked]))
        assert w.start_by_map.margin_ll is None or w.start_by_map.margin_ll >= 0
        assert w.start_by_map.near in LandmarkGraph.load(b / "graph.yaml").ids
        needs = md.split("## Needs the surveyor")[1]
        row = next(ln for ln in needs.splitlines()
                   if ln.startswith(f"| {w.key} |") and "inferred as the start" in ln)  # fmt: skip
        assert f"`{w.name}: LANDMARK`" in row and "buildings.mall.starts" in row
        assert f"{ranked[0][0]} {ranked[0][1]:g} m" in row
        # the command that opens it in the panel on the building's merged map, which --map reads
        cmd = shlex.split(w.edit_command)
        assert f"`{w.edit_command}`" in row and cmd[:2] == ["workstation", "edit"]
        assert cmd[cmd.index("--map") + 1] == str(out / "radiomap" / "building=mall")
    merged = Fingerprints.read(out / "radiomap" / "building=mall")
    assert len(merged) == rep.buildings["mall"].reference_points
    assert set(np.unique(merged.floor)) == {0.0}
    saved = json.loads((out / "campaign.json").read_text())
    assert saved["per_walk"] == json.loads(json.dumps([w.to_json() for w in rep.per_walk]))


def test_a_campaign_output_that_is_a_file_or_a_pipe_is_refused_as_such(tmp_path, capsys):
    """Issue #67 item 5: `campaign run --out` given a file or a FIFO said "free the space and
    run the same command again"; it says the output is no folder, and writes nothing."""
    import os

    from workstation.cli import main

    root, _, _, _ = _mall_campaign(tmp_path, 0)
    f, fifo = tmp_path / "out.txt", tmp_path / "pipe"
    f.write_text("mine")
    os.mkfifo(fifo)
    for out in (f, fifo):
        assert main(["campaign", "run", str(root), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert f"{out}: is not a folder" in err and "free the space" not in err
    assert f.read_text() == "mine"
