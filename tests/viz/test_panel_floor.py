"""The panel opens on the walk (issue #64 item 5): on the floor where the walk spends most of
its time, framed on it; a floor chosen in the dropdown is framed again on the walk there."""

import time

import numpy as np

from tests.conftest import IPIN, need
from workstation.editor import SurveyEditor
from workstation.graph.importers import graph_from_tra
from workstation.params import Params
from workstation.pipeline.start import resolve_start
from workstation.session import load_session
from workstation.viz.panel import SurveyPanel

WALK = "IPIN2023_T3_TrainingTrial51_repetition02.txt"  # the README's museum walk


def test_the_panel_opens_on_the_floor_the_walk_spends_most_time_on_and_reframes(tmp_path):
    tra = sorted((need(IPIN) / "supplementary" / "trajectories").glob("*.tra"))
    graph = graph_from_tra(tra)
    s = load_session(IPIN / "logfiles" / WALK)
    p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})
    ed = SurveyEditor(s, graph, p, out_dir=tmp_path)
    tr = ed.result.track
    on = tr.steps.segment >= 0
    floors, n = np.unique(tr.steps.floor[on], return_counts=True)
    most = float(floors[np.argmax(n)])
    assert graph.node(tr.start.node).floor != most  # the case the issue found: it starts elsewhere
    panel = SurveyPanel(ed, None, port=0)
    try:
        assert panel.floor == most
        (hx, hy), ext = panel.home
        there = on & (tr.steps.floor == most)
        assert (
            abs(hx - np.median(tr.steps.x[there])) < ext
            and abs(hy - np.median(tr.steps.y[there])) < ext
        )
        other = next(f for f in floors if f != most)
        panel.floor_dd.value = f"{other:g}"  # the dropdown, as a tab changes it
        deadline = time.time() + 10
        while panel.floor != other and time.time() < deadline:
            time.sleep(0.05)
        assert panel.floor == other
        (gx, gy), ext2 = panel.home
        here = on & (tr.steps.floor == other)
        assert (gx, gy) != (hx, hy)
        assert (
            abs(gx - np.median(tr.steps.x[here])) < ext2
            and abs(gy - np.median(tr.steps.y[here])) < ext2
        )
    finally:
        panel.stop()
