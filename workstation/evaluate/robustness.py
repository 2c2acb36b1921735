"""Robustness and reference-point density on the simulated office (realistic model by default).

Robustness: the walk simulated on the true building, the pipeline run on a graph with the
errors a surveyor makes (landmarks displaced by N(0, 0.5 m) and N(0, 1.5 m), 20 % of the rules
forgotten, an edge left out), on a walk without door stops, on the varied walk and in the
three-floor office (floors 3.1 and 2.4 m apart, one flight from floor 0 to 2; the graph does
not state the heights, so the spacings are learnt); each association mode; 10 seeds. A walk is *lost* when its mean trajectory error exceeds 5 m.

Density: our radio map from the normal walk scanned every 2–4 s, 1–2 s and 0.5–1 s against the
manual 5- and 10-scan surveys, every map localizing the held-out walk (1-NN, the parameters'
``localize`` section).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..localize import Fingerprints, errors, localize
from ..params import Params
from ..pipeline import Pipeline
from ..sim import simulate
from ..sim.building import office2f, office3f
from ..sim.graph_errors import perturb_graph

LOST_M = 5.0
CONDITIONS = {
    "clean": {},
    "nodes displaced 0.5 m": {"displace_sd_m": 0.5},
    "nodes displaced 1.5 m": {"displace_sd_m": 1.5},
    "20 % rules removed": {"drop_rules": 0.2},
    "one edge missing": {"drop_edges": 1},
    "no door stops": {"walk": "no_door_stops"},
    "varied walk": {"walk": "varied"},
    "3 floors unevenly spaced, one flight over two": {"walk": "office3f"},
}
MODES = ("hmm", "greedy")
INTERVALS = ((2.0, 4.0), (1.0, 2.0), (0.5, 1.0))


@dataclass(frozen=True)
class RobustnessRow:
    condition: str
    association: str
    seeds: int
    mean_m: float  # mean over seeds of the walk's mean trajectory error
    p90_m: float  # over all steps of all seeds
    lost: int
    floor_accuracy: float  # share of steps on the right floor, mean over seeds


@dataclass(frozen=True)
class DensityRow:
    radio_map: str
    reference_points: float  # mean over seeds
    mean_m: float  # 1-NN error where the floor is right, mean over seeds
    mean_with_floor_penalty_m: float
    floor_accuracy: float


def robustness(
    seeds: int = 10, model: str = "realistic", params: Params | None = None, progress=None
) -> list[RobustnessRow]:
    params = params or Params()
    b = office2f()
    b3 = office3f()
    start = b.routes["survey"][0]
    errs: dict[tuple[str, str], list[np.ndarray]] = {}
    floors: dict[tuple[str, str], list[float]] = {}
    for i, seed in enumerate(range(1, seeds + 1)):
        walks = {
            "normal": simulate(b, "normal", seed, model),
            "varied": simulate(b, "varied", seed, model),
            "no_door_stops": simulate(b, "normal", seed, model, door_stops=False),
            "office3f": simulate(b3, "normal", seed, model),
        }
        for name, cond in CONDITIONS.items():
            cond = dict(cond)
            sim = walks[cond.pop("walk", "normal")]
            g = perturb_graph(sim.graph, np.random.default_rng(1000 + seed), **cond)
            for mode in MODES:
                p = params.updated(**{"pdr.start_node": start, "pdr.association": mode})
                r = Pipeline(sim.session, g, p).run()
                gt = sim.session.ground_truth
                tr = r.track
                m = tr.segment >= 0
                gx, gy, _ = gt.at(tr.t[m])
                errs.setdefault((name, mode), []).append(np.hypot(tr.x[m] - gx, tr.y[m] - gy))
                fl = gt.at(tr.t[m])[2]
                floors.setdefault((name, mode), []).append(float(np.mean(tr.floor[m] == fl)))
        if progress:
            progress(i + 1, seeds, f"robustness seed {seed}")
    rows = []
    for (name, mode), e in errs.items():
        means = np.array([x.mean() if x.size else np.inf for x in e])
        allv = np.concatenate(e) if e else np.empty(0)
        rows.append(
            RobustnessRow(
                name,
                mode,
                len(e),
                round(float(means.mean()), 3),
                round(float(np.percentile(allv, 90)), 3) if allv.size else float("nan"),
                int((means > LOST_M).sum()),
                round(float(np.mean(floors[(name, mode)])), 4),
            )  # fmt: skip
        )
    return rows


def density(
    seeds: int = 3, model: str = "realistic", params: Params | None = None, progress=None
) -> list[DensityRow]:
    params = params or Params()
    lp = params.localize
    b = office2f()
    res: dict[str, list[dict]] = {}
    for i, seed in enumerate(range(1, seeds + 1)):
        queries = Fingerprints.from_session(simulate(b, "heldout", seed, model).session)
        maps = {}
        for lo, hi in INTERVALS:
            sim = simulate(b, "normal", seed, model, (lo, hi))
            p = params.updated(**{"pdr.start_node": b.routes["survey"][0]})
            r = Pipeline(sim.session, b.graph, p).run()
            maps[f"Ours, a scan every {lo:g}–{hi:g} s"] = Fingerprints.from_radiomap(r.radiomap)
        for k in (5, 10):
            maps[f"Manual ({k} scans)"] = Fingerprints.from_session(
                simulate(b, f"survey{k}", seed, model).session
            )
        for name, fp in maps.items():
            est = localize(fp, queries, lp.metric, k=lp.k, tau=lp.tau_dbm,
                           align_device=lp.align_devices)  # fmt: skip
            res.setdefault(name, []).append(errors(est, queries) | {"rps": len(fp)})
        if progress:
            progress(i + 1, seeds, f"density seed {seed}")
    return [
        DensityRow(
            name,
            round(float(np.mean([x["rps"] for x in v])), 1),
            round(float(np.mean([x.get("mean_m", np.nan) for x in v])), 3),
            round(float(np.mean([x["mean_with_floor_penalty_m"] for x in v])), 3),
            round(float(np.mean([x["floor_accuracy"] for x in v])), 4),
        )
        for name, v in res.items()
    ]
