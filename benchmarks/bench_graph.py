"""Reachability (the candidates of every landmark) on grid graphs with many rule-less landmarks
(one landmark in nine has a rule): 100, 1,000 and 10,000 nodes. The exhaustive search this
replaced took 15 s at 100 nodes and never finished at 10,000."""

from __future__ import annotations

from _common import Table, median_of


def grid(n: int):
    from workstation.sim.building import grid_graph

    return grid_graph(n)


def run() -> Table:
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.reach import Reach
    from workstation.sim import simulate

    def every(g):
        r = Reach(g, 3)
        for v in g.ids:
            r.routes_from(v)

    t = Table("Grid graphs with many rule-less landmarks (max_hops 3)")
    for n, rep in ((10, 5), (32, 3), (100, 1)):
        g = grid(n)
        med, _ = median_of(lambda g=g: every(g), rep)
        t.add(f"{n * n:,} landmarks: routes from every landmark", med, "s", "{:,.2f}")
    # the office walk on the 10,000-node grid (it fits nowhere: the worst case for the search)
    sim, g = simulate("office2f", "normal", 1), grid(100)
    med, _ = median_of(lambda: Pipeline(sim.session, g, Params()).run(), 1)
    t.add("10,000 landmarks: a 5.5-min walk, start inferred", med, "s", "{:,.1f}")
    p = Params().updated(**{"pdr.start_node": "n45_3"})
    med, _ = median_of(lambda: Pipeline(sim.session, g, p).run(), 3)
    t.add("10,000 landmarks: the same walk, start given (an editor re-run)", med, "s", "{:,.2f}")
    _panel(t, sim, g)
    return t


def _panel(t: Table, sim, g) -> None:
    """The survey panel on the 10,000-landmark grid (all on one floor): up, then a node moved
    and the panel redrawn (the median of 5)."""
    import tempfile
    import time
    from pathlib import Path

    from workstation.editor import SurveyEditor
    from workstation.params import Params
    from workstation.viz.panel import SurveyPanel

    tmp = Path(tempfile.mkdtemp())
    gp = tmp / "grid.yaml"
    g.save(gp)
    p = Params().updated(**{"pdr.start_node": "n45_3"})
    ed = SurveyEditor(sim.session, g, params=p, graph_path=gp, out_dir=tmp)
    t0 = time.perf_counter()
    pan = SurveyPanel(ed, None, port=0)
    t.add("10,000 landmarks: survey panel up", time.perf_counter() - t0, "s", "{:,.1f}")
    dx = iter([0.3, 0.0] * 5)
    try:

        def move():
            ed.move_node("n50_50", 250.0 + next(dx), 250.0)
            pan.after_edit()

        med, _ = median_of(move, 5)
        t.add("10,000 landmarks: node move → panel redrawn", med, "s", "{:,.2f}")
    finally:
        pan.stop()


if __name__ == "__main__":
    run().print()
