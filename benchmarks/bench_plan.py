"""Survey plans (issue #32): time to plan and the route against its matching lower bound on the
office, museum and mall F1 graphs (bar: ≤ 1 s, within 1 %); the simulated walker walking the
office plans over 10 seeds (edges with accepted points, tracking error beside the bundled
route's); the museum walks' predicted durations (bar: each within 20 %)."""

from __future__ import annotations

import numpy as np
from _common import REPO, SHARED_DATA, Table, median_of


def _graphs():
    from workstation.evaluate.walks import ipin_museum
    from workstation.graph import LandmarkGraph
    from workstation.sim.building import office2f, office3f

    out = {"office2f": office2f().graph, "office3f": office3f().graph}
    museum = ipin_museum(SHARED_DATA)
    if museum is not None:
        out["museum"] = museum[1]
    out["mall F1"] = LandmarkGraph.load(REPO / "tests" / "data" / "msilc" / "site1_f1_graph.yaml")
    return out


def _simulated(t: Table) -> None:
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.sim import simulate
    from workstation.sim.building import BUILDINGS
    from workstation.survey_plan.check import edge_cover, track_error
    from workstation.survey_plan.plan import plan_survey

    for name in ("office2f", "office3f"):
        b = BUILDINGS[name]()
        route = tuple(v.node for v in plan_survey(b.graph).walks[0].visits)
        cover, ep, eb = [], [], []
        for seed in range(1, 11):
            sim = simulate(name, "normal", seed, route=route)
            p = Params().updated(**{"pdr.start_node": route[0]})
            r = Pipeline(sim.session, sim.graph, p).run()
            cover.append(edge_cover(b.graph, r.radiomap))
            ep.append(track_error(sim.session, r))
            base = simulate(name, "normal", seed)
            pb = Params().updated(**{"pdr.start_node": b.routes["survey"][0]})
            eb.append(track_error(base.session, Pipeline(base.session, base.graph, pb).run()))
        t.add(
            f"{name}, walking the plan: edges with accepted points, min of 10",
            100 * min(cover),
            "%",
        )
        t.add(
            f"{name}: tracking error, plan / bundled route (mean of 10)",
            np.mean(ep),
            f"m / {np.mean(eb):.2f} m",
            "{:.2f}",
        )


def _museum(t: Table) -> None:
    from workstation.evaluate.walks import ipin_museum
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.start import resolve_start
    from workstation.session import load_session
    from workstation.survey_plan.check import durations

    museum = ipin_museum(SHARED_DATA)
    if museum is None:
        return
    logs, graph = museum
    ss = [load_session(p).in_frame(graph.frame) for p in logs]
    rs = [Pipeline(s, graph, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})).run()
          for s in ss]  # fmt: skip
    err = np.array([r["error"] for r in durations(graph, ss, rs)])
    t.add(
        "museum: predicted duration of each walk's route, worst |error|",
        100 * np.abs(err).max(),
        "%",
    )
    t.add("museum: mean |error| over the 10 walks", 100 * np.abs(err).mean(), "%")


def run() -> Table:
    from workstation.survey_plan.plan import plan_survey

    t = Table("Survey plans: route vs matching bound, time to plan (bar ≤ 1 s, ≤ 1 %)")
    for name, g in _graphs().items():
        med, iqr = median_of(lambda g=g: plan_survey(g, max_minutes=5), 5)
        p = plan_survey(g, max_minutes=5)
        t.add(
            f"{name}: plan ({len(g.nodes)} landmarks), median",
            1e3 * med,
            f"ms (IQR {1e3 * iqr:.0f})",
        )
        t.add(f"{name}: route / matching bound", p.route_s / p.bound_s, "", "{:.4f}")
    _simulated(t)
    _museum(t)
    return t


if __name__ == "__main__":
    run().print()
