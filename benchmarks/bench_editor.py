"""Editor latency as the surveyor meets it: the new result ready after a belief-threshold change
and after a node move, with the Rerun observer attached (recording to a file, as ``edit --save``)
and the start inferred (as ``edit`` does without ``--start``); then with the viser panel
redrawing its scene. On the bundled ≈5.5-minute simulated walk, and on the real museum walk
Trial51 (stairs 0 → −1 → −2, 5 min) when ../shared/data is there. Medians and IQR."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
from _common import REPO, SHARED_DATA, Table, median_of

from workstation.building.floorplan import FloorPlan
from workstation.editor import SurveyEditor
from workstation.graph import LandmarkGraph
from workstation.session import load_session

SIM = REPO / "sample_sessions" / "office2f" / "normal"
IPIN = SHARED_DATA / "ipin2023-track3"
TRIAL51 = IPIN / "logfiles" / "IPIN2023_T3_TrainingTrial51_repetition02.txt"


def _editor(session, graph_path: Path, tmp: Path, rrd: Path) -> SurveyEditor:
    from workstation.viz.rerun_log import RerunLogger, new_recording

    graph = LandmarkGraph.load(graph_path)
    rec = new_recording()
    rec.save(str(rrd))
    obs = RerunLogger(rec, session, graph, None, None)
    return SurveyEditor(session, graph, graph_path=graph_path, out_dir=tmp, observers=[obs])


def _walks(tmp: Path):
    g = tmp / "office.yaml"
    shutil.copy(SIM / "graph.yaml", g)
    yield (
        "simulated office, 5.5 min",
        load_session(SIM),
        g,
        "DS0",
        FloorPlan.load(SIM / "floorplan.yaml"),
    )
    if TRIAL51.is_file():
        from workstation.graph.importers import graph_from_tra

        m = tmp / "museum.yaml"
        graph_from_tra(sorted((IPIN / "supplementary" / "trajectories").glob("*.tra"))).save(m)
        yield "IPIN museum Trial51, 5 min", load_session(TRIAL51), m, "L74", None


def _measure(tab: Table, name: str, ed: SurveyEditor, node: str, plan) -> None:
    y = ed.graph.node(node).y
    ths = iter(np.linspace(10, 40, 400))
    dx = iter(np.tile([0.3, -0.3], 200))

    def threshold():
        ed.set_param("belief.threshold", float(next(ths)))

    def move():
        ed.move_node(node, ed.graph.node(node).x + float(next(dx)), y)

    for label, fn in (("belief-threshold change → result", threshold),
                      (f"node move ({node} ±0.3 m) → result", move)):  # fmt: skip
        med, iqr = median_of(fn, 11)
        tab.add(f"{name}: {label}", med * 1e3, "ms", "{:,.1f}")
        tab.add("    IQR", iqr * 1e3, "ms", "{:,.1f}")
    from workstation.viz.panel import SurveyPanel

    panel = SurveyPanel(ed, plan, port=0)
    try:

        def move_and_redraw():
            move()
            panel.after_edit()

        med, iqr = median_of(move_and_redraw, 7)
        tab.add(f"{name}: node move → panel redrawn", med * 1e3, "ms", "{:,.1f}")
        tab.add("    IQR", iqr * 1e3, "ms", "{:,.1f}")
    finally:
        panel.stop()


def run() -> Table:
    tab = Table("Survey editor, Rerun observer attached, start inferred (median ± IQR)")
    tmp = Path(tempfile.mkdtemp())
    for name, session, gpath, node, plan in _walks(tmp):
        ed = _editor(session, gpath, tmp, tmp / f"{gpath.stem}.rrd")
        _measure(tab, name, ed, node, plan)
    return tab
