"""Robustness and reference-point density on the simulated office (realistic model by default).

Robustness: the walk simulated on the true building, the pipeline run on a graph with the
errors a surveyor makes (landmarks displaced by N(0, 0.5 m) and N(0, 1.5 m), 20 % of the rules
forgotten, an edge left out), on a walk without door stops, on the varied walk and in the
three-floor office (floors 3.1 and 2.4 m apart, one flight from floor 0 to 2; the graph does
not state the heights, so the spacings are learnt); each association mode; 10 seeds. A walk is *lost* when its mean trajectory error exceeds 5 m.

Density: our radio map from the normal walk (361 m, the paper's test path is 362 m) scanned every
2–4 s, 1–2 s, 0.5–1 s and 0.4–0.8 s — the last gives the paper's density, ≈ 610 reference points
(the paper: 609) — against the manual 5- and 10-scan surveys (a point every 1.5 m, each scan a
reference point), every map localizing the held-out walk (1-NN, the parameters' ``localize``
section). Beside them, where the gap to the manual survey comes from, on the 0.4–0.8 s walk:
every scan kept where we placed it (no filter), our accepted scans at their true positions
(placement taken out), and every scan at its true position (the ceiling of a walk survey).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from workstation.fingerprints.localize import Fingerprints, errors, localize
from workstation.fingerprints.matchers import of_params
from workstation.fingerprints.standby import joins
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.sim import GRID_STEP_M, simulate, survey_points
from workstation.sim.building import office2f, office3f
from workstation.sim.graph_errors import perturb_graph

LOST_M = 5.0
CONDITIONS: dict[str, dict[str, Any]] = {
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
INTERVALS = ((2.0, 4.0), (1.0, 2.0), (0.5, 1.0), (0.4, 0.8))
PAPER_DENSITY = (0.4, 0.8)  # ≈ 610 reference points on the 361-m walk; the paper: 609 on 362 m
CEILING = "Every scan of that walk at its true position (oracle)"
UNFILTERED = "That walk, every scan kept where we placed it (no filter)"
ACCEPTED_AT_TRUTH = "That walk, our accepted scans at their true positions"


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
    seeds: int
    reference_points: float  # mean over seeds
    per_metre: float  # reference points per metre of the walk (the manual survey: of its route)
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
                assert gt is not None  # a simulated walk has its ground truth
                st = r.track.steps
                m = st.segment >= 0
                gx, gy, _ = gt.at(st.t[m])
                errs.setdefault((name, mode), []).append(np.hypot(st.x[m] - gx, st.y[m] - gy))
                fl = gt.at(st.t[m])[2]
                floors.setdefault((name, mode), []).append(float(np.mean(st.floor[m] == fl)))
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
        maps, length = {}, {}
        for lo, hi in INTERVALS:
            sim = simulate(b, "normal", seed, model, (lo, hi))
            p = params.updated(**{"pdr.start_node": b.routes["survey"][0]})
            r = Pipeline(sim.session, b.graph, p).run()
            name = f"Ours, a scan every {lo:g}–{hi:g} s" + (
                " (the paper's density)" if (lo, hi) == PAPER_DENSITY else ""
            )
            maps[name] = Fingerprints.of_walk(r.radiomap)
            gt = sim.session.ground_truth
            assert gt is not None
            length[name] = float(np.hypot(np.diff(gt.x), np.diff(gt.y)).sum())
            if (lo, hi) == PAPER_DENSITY:  # where the gap to the manual survey comes from
                rm, gt = r.radiomap, sim.session.ground_truth
                assert gt is not None
                walked = rm.segment >= 0
                maps[UNFILTERED] = Fingerprints.from_radiomap(rm, None, False)
                # the rows of our map (its points and the scans on standby that joined it)
                mine = Fingerprints.from_radiomap(rm, standby=True)
                kept = ~mine.on_standby | joins(mine.x, mine.y, mine.floor, mine.on_standby,
                                                 sigma=mine.sigma)
                t_kept = rm.t[rm.accepted | rm.held_for_sigma][kept]
                maps[ACCEPTED_AT_TRUTH] = _at_truth(
                    replace(mine.subset(kept), standby=None), gt, t_kept
                )
                maps[CEILING] = _at_truth(Fingerprints.from_radiomap(rm, None, False), gt,
                                          rm.t[walked])  # fmt: skip
                for k in (UNFILTERED, ACCEPTED_AT_TRUTH, CEILING):
                    length[k] = length[name]
        route = survey_points(b)
        for n_scans in (5, 10):
            name = f"Manual ({n_scans} scans)"
            walk = simulate(b, f"survey{n_scans}", seed, model)
            maps[name] = Fingerprints.from_session(walk.session)
            length[name] = float(route.shape[0] * GRID_STEP_M)
        for name, fp in maps.items():
            est = localize(fp, queries, tau=lp.tau_dbm, align_device=lp.align_devices,
                           matcher=of_params(lp))  # fmt: skip
            res.setdefault(name, []).append(
                errors(est, queries) | {"rps": len(fp), "per_m": len(fp) / length[name]}
            )
        if progress:
            progress(i + 1, seeds, f"density seed {seed}")
    return [
        DensityRow(
            name,
            len(v),
            round(float(np.mean([x["rps"] for x in v])), 1),
            round(float(np.mean([x["per_m"] for x in v])), 2),
            round(float(np.mean([x.get("mean_m", np.nan) for x in v])), 3),
            round(float(np.mean([x["mean_with_floor_penalty_m"] for x in v])), 3),
            round(float(np.mean([x["floor_accuracy"] for x in v])), 4),
        )
        for name, v in res.items()
    ]


def _at_truth(fp: Fingerprints, gt, t: np.ndarray) -> Fingerprints:
    x, y, f = gt.at(t)
    return dataclasses.replace(fp, x=x, y=y, floor=np.asarray(f, fp.floor.dtype))
