"""A campaign walk's fix written from the panel (workstation/io/walk_fixes.py): "Start here" and
"End here" write the walk's entry to the building's starts.yaml / ends.yaml, which the campaign
reads; "Infer the start again" takes it out; a broken file is named and left alone."""

from __future__ import annotations

import sys

from tests.conftest import REPO
from workstation.campaign.layout import _starts
from workstation.io.walk_fixes import WalkFixes
from workstation.io.yamlio import load_yaml

MALL = REPO / "tests" / "data" / "msilc"


def test_the_entry_is_written_changed_and_taken_out(tmp_path):
    starts = tmp_path / "starts.yaml"
    fx = WalkFixes("walk03", starts, None)
    said = fx.record("start", "L12")
    assert "written to" in said and "walk03: L12" in said
    assert _starts(load_yaml(starts, "walk starts"), starts, "") == (("walk03", "L12"),)
    starts.write_text("other: L5\nwalk03: L12\n")
    fx.record("start", "L14")
    assert load_yaml(starts, "s") == {"other": "L5", "walk03": "L14"}
    assert load_yaml(starts.with_name("starts.yaml.bak"), "s") == {"other": "L5", "walk03": "L12"}
    assert "taken out" in fx.record("start", None)
    assert load_yaml(starts, "s") == {"other": "L5"}
    assert fx.record("start", None) == ""  # nothing to take out
    assert fx.record("end", "L3") == "" and not (tmp_path / "ends.yaml").exists()  # no ends file
    # a walk name YAML would read as a number stays a name
    WalkFixes("0012", starts, None).record("start", "L7")
    assert ("0012", "L7") in _starts(load_yaml(starts, "s"), starts, "")


def test_a_broken_file_is_named_and_left_alone(tmp_path):
    ends = tmp_path / "ends.yaml"
    ends.write_text("- a list\n- not a mapping\n")
    said = WalkFixes("w", None, ends).record("end", "L1")
    assert "NOT updated" in said and str(ends) in said
    assert ends.read_text() == "- a list\n- not a mapping\n"
    ends.write_text("w: [L1\n")
    said = WalkFixes("w", None, ends).record("end", "L1")
    assert "NOT updated" in said and f"{ends}:2:" in said


def test_the_panel_buttons_write_the_campaign_files(tmp_path, monkeypatch):
    """A folder campaign with a real mall walk recorded without taps (the bundled session, its
    fixes removed: its start is inferred, and ambiguous): campaign.md's command opens it with
    its campaign files; the editor so opened writes 'Start here' to starts.yaml and 'End here'
    to ends.yaml, and the next run takes them; 'Infer the start again' and finding the end
    again take them out."""
    import shutil

    from workstation.campaign import run_campaign
    from workstation.editor import SurveyEditor
    from workstation.graph import LandmarkGraph
    from workstation.session import load_session

    monkeypatch.setitem(sys.modules, "distributed", None)
    b = tmp_path / "c" / "buildings" / "mall"
    walk = b / "walks" / "w1"
    shutil.copytree(REPO / "sample_sessions" / "msilc-site1-f1-walk", walk)
    (walk / "ground_truth.parquet").unlink()
    meta = walk / "session.yaml"
    meta.write_text(meta.read_text().replace("  ground_truth: ground_truth.parquet\n", ""))
    shutil.copy(MALL / "site1_f1_graph.yaml", b / "graph.yaml")
    run = lambda: run_campaign(tmp_path / "c", tmp_path / "out", workers=1, say=lambda s: None)  # noqa: E731
    w = run().per_walk[0]
    assert any(q.reason == "start_ambiguous" for q in w.quarantine), w
    cmd = w.edit_command
    assert f"--campaign-walk w1 --starts-file {b / 'starts.yaml'}" in cmd
    assert f"--ends-file {b / 'ends.yaml'}" in cmd
    md = (tmp_path / "out" / "campaign.md").read_text()
    assert f"writes `w1: LANDMARK` to {b / 'starts.yaml'}" in md
    # the editor as that command opens it
    g = LandmarkGraph.load(b / "graph.yaml")
    ed = SurveyEditor(load_session(walk), g, graph_path=tmp_path / "g.yaml", out_dir=tmp_path / "o")
    ed.fixes = WalkFixes("w1", b / "starts.yaml", b / "ends.yaml")
    start = w.candidates[1]
    assert ed.set_start(start) and "written to" in ed.message
    end = ed.result.track.end.node or ed.result.track.segments.from_node[-1]
    assert ed.set_end(end)
    assert load_yaml(b / "starts.yaml", "s") == {"w1": start}
    assert load_yaml(b / "ends.yaml", "s") == {"w1": end}
    w = run().per_walk[0]
    assert w.summary.start_node == start and w.summary.end.node == end
    ed.infer_start()
    assert "taken out" in ed.message and load_yaml(b / "starts.yaml", "s") == {}
    assert ed.set_end(None) and load_yaml(b / "ends.yaml", "s") == {}
