"""Editor latency on a ≈5.5-minute walk: the new result ready after a belief-threshold change
and after a node move (editor state, and with the viser panel redrawing its scene)."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np
from _common import REPO, Table, best_of

from workstation.editor import SurveyEditor
from workstation.floorplan import FloorPlan
from workstation.graph import LandmarkGraph
from workstation.session import load_session

WALK = REPO / "sample_sessions" / "office2f" / "normal"


def run() -> Table:
    tab = Table("Survey editor (5.5 min walk)")
    tmp = Path(tempfile.mkdtemp())
    shutil.copy(WALK / "graph.yaml", tmp / "graph.yaml")
    ed = SurveyEditor(
        load_session(WALK),
        LandmarkGraph.load(tmp / "graph.yaml"),
        graph_path=tmp / "graph.yaml",
        out_dir=tmp,
    )
    ths = iter(np.linspace(10, 40, 400))
    tab.add(
        "belief-threshold change → result",
        best_of(lambda: ed.set_param("belief.threshold", float(next(ths))), 20) * 1e3,
        "ms",
        "{:,.1f}",
    )
    xs = iter(np.linspace(39, 41, 400))
    tab.add(
        "node move → result",
        best_of(lambda: ed.move_node("DS0", float(next(xs)), 10.0), 20) * 1e3,
        "ms",
        "{:,.1f}",
    )
    from workstation.viz.panel import SurveyPanel

    panel = SurveyPanel(ed, FloorPlan.load(WALK / "floorplan.yaml"), port=0)
    try:

        def move_and_redraw():
            ed.move_node("DS0", float(next(xs)), 10.0)
            panel.after_edit()

        def threshold_and_redraw():
            ed.set_param("belief.threshold", float(next(ths)))
            panel.after_edit(params_changed=True)

        tab.add(
            "belief-threshold change → panel redrawn",
            best_of(threshold_and_redraw, 10) * 1e3,
            "ms",
            "{:,.1f}",
        )
        tab.add("node move → panel redrawn", best_of(move_and_redraw, 10) * 1e3, "ms", "{:,.1f}")
    finally:
        panel.stop()
    return tab
