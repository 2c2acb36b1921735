"""Issue #33: temporary files of a killed save or campaign are removed on the next start —
only ours (the atomic writer's names), never the user's files."""

import shutil

from tests.conftest import REPO
from workstation.io.atomic import sweep_leftovers

WALK = REPO / "sample_sessions" / "office2f" / "normal"


def _litter(folder):
    left = [folder / ".graph.yaml.ab12_xYz.tmp", folder / ".graph.yaml.bak.q1w2e3r4.tmp"]
    keep = [folder / "graph.yaml.tmp", folder / ".notes.txt", folder / ".graph.yaml.short.tmp",
            folder / "mine.ab12_xYz.tmp"]  # fmt: skip
    for p in left + keep:
        p.write_text("x")
    return left, keep


def test_the_editor_removes_a_killed_saves_temporary_files(tmp_path):
    from workstation.editor import SurveyEditor
    from workstation.graph import LandmarkGraph
    from workstation.session import load_session

    g = tmp_path / "graph.yaml"
    shutil.copy(WALK / "graph.yaml", g)
    left, keep = _litter(tmp_path)
    ed = SurveyEditor(load_session(WALK), LandmarkGraph.load(g), graph_path=g,
                      out_dir=tmp_path / "out")  # fmt: skip
    assert not any(p.exists() for p in left)
    assert all(p.exists() for p in keep)
    assert "removed 2 temporary file(s)" in ed.message


def test_a_campaign_start_removes_a_killed_runs_leftovers(tmp_path):
    out = tmp_path / "out"
    (out / "walks" / "b").mkdir(parents=True)
    half = out / "radiomap" / ".building=b.k9k9k9k9"  # a folder being built when killed
    half.mkdir(parents=True)
    (half / "part.parquet").write_text("x")
    tmp = out / "walks" / "b" / ".queries.parquet.a1b2c3d4.tmp"
    tmp.write_text("x")
    mine = out / "walks" / "b" / "notes.md"
    mine.write_text("x")
    removed = sweep_leftovers(out, recursive=True, own=True)
    assert set(removed) == {half, tmp} and mine.exists() and not half.exists()
