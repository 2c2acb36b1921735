"""The paper's experiments on the simulated two-floor office (dense ground truth): trajectory
error CDF per method (Fig. 5), 1-NN error against segment belief (Fig. 6), floor accuracy and mean
1-NN error per radio-map method and metric (Figs. 7–8), mean error against τ (Fig. 9), survey
time per method (Table II)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from workstation.baselines import Trajectory
from workstation.baselines.particles import particle_filter
from workstation.baselines.pdr import pdr
from workstation.baselines.tap import tap_interpolation
from workstation.fingerprints.localize import Fingerprints, Metric, errors, localize
from workstation.params import COMPASS_HEADING, GYRO_HEADING, Params
from workstation.pipeline import Pipeline
from workstation.pipeline.radiomap import RadioMap
from workstation.pipeline.summary import Summary
from workstation.sim import simulate
from workstation.sim.building import office2f

# Table II time model (minutes), stated rather than measured: drawing a landmark graph or the
# walls from a floor plan takes about ten minutes (the paper's figure); a manual survey point
# is measured and marked in 25 s and each point needs its stationary scans (2 s a scan) and
# 8 s to move to it (the simulator's survey model).
SETUP_GRAPH_MIN = 10.0
SETUP_PER_MANUAL_POINT_S = 25.0
TAUS = tuple(range(-100, -55, 5))

#: a map's 1-NN errors as :func:`~workstation.fingerprints.localize.errors` gives them
Errors = dict[str, float | None]


@dataclass(frozen=True)
class MapErrors:
    """One radio-map method of Figs. 7–8: its reference points, its errors per metric."""

    reference_points: int
    euclidean: Errors
    sorensen: Errors

    def under(self, metric: Metric) -> Errors:
        return self.euclidean if metric is Metric.EUCLIDEAN else self.sorensen


@dataclass(frozen=True)
class BeliefBin:
    """Fig. 6: the map of the points whose segment's belief reaches ``belief``: how many, how
    far they are placed from the truth, its 1-NN errors (empty without a point)."""

    belief: str  # "≥ 18"
    reference_points: int
    rp_error_mean_m: float | None
    errors: Errors

    def to_json(self) -> dict[str, Any]:
        return {"belief": self.belief, "reference_points": self.reference_points,
                "rp_error_mean_m": self.rp_error_mean_m, **self.errors}  # fmt: skip


@dataclass(frozen=True)
class BeliefSplit:
    """Fig. 6: the placement errors of the points at most and above the threshold ε_S."""

    threshold: float
    at_most: dict[str, float]  # mean_m, median_m, p90_m, n
    above: dict[str, float]


@dataclass(frozen=True)
class Simulated:
    """The paper's experiments on the simulated office (results.json's ``simulated``; the
    samples the figures draw are not in it)."""

    walk_length_m: float
    trajectory_error: dict[str, dict[str, float]]  # per method: mean_m, median_m, p90_m
    radio_maps: dict[str, MapErrors]
    tau_sweep_sorensen_mean_m: dict[str, dict[int, float | None]]  # per map, per τ
    tau_dbm: float
    belief_bins: tuple[BeliefBin, ...]
    rp_error_by_belief: BeliefSplit
    survey_time: dict[str, dict[str, float]]  # per method: setup_min, collection_min
    ours_summary: Summary
    trajectory_error_samples: dict[str, np.ndarray] = field(repr=False)  # Fig. 5
    belief_scatter: tuple[tuple[np.ndarray, np.ndarray], ...] = field(repr=False)  # Fig. 6

    def to_json(self) -> dict[str, Any]:
        return {
            "walk_length_m": self.walk_length_m, "trajectory_error": self.trajectory_error,
            "radio_maps": {k: asdict(v) for k, v in self.radio_maps.items()},
            "tau_sweep_sorensen_mean_m": self.tau_sweep_sorensen_mean_m, "tau_dbm": self.tau_dbm,
            "belief_bins": [b.to_json() for b in self.belief_bins],
            "rp_error_by_belief": asdict(self.rp_error_by_belief),
            "survey_time": self.survey_time, "ours_summary": self.ours_summary.to_json(),
        }  # fmt: skip


def _stats(e: np.ndarray) -> dict[str, float]:
    if e.size == 0:
        return {}
    return {
        "mean_m": round(float(e.mean()), 3),
        "median_m": round(float(np.median(e)), 3),
        "p90_m": round(float(np.percentile(e, 90)), 3),
    }


def _ours_trajectory(result) -> Trajectory:
    tr = result.track
    m = tr.steps.segment >= 0
    return Trajectory(tr.steps.t[m], tr.steps.x[m], tr.steps.y[m], tr.steps.floor[m])


def simulated(seed: int = 1, params: Params | None = None, model: str = "realistic") -> Simulated:
    params = params or Params()
    eps, tau = params.belief.threshold, params.localize.tau_dbm
    b = office2f()
    sims = {
        w: simulate(b, w, seed, model)
        for w in ("normal", "varied", "heldout", "survey5", "survey10")
    }
    normal = sims["normal"].session
    res = Pipeline(normal, b.graph, params).run()
    start = b.graph.node(res.track.start.node)
    sxy = (start.x, start.y)
    known = np.array(b.graph.floors)
    methods = {
        "Landmark graph (ours)": _ours_trajectory(res),
        "PDR I (compass)": pdr(normal, sxy, start.floor, COMPASS_HEADING, known_floors=known),
        "PDR II (gyro)": pdr(normal, sxy, start.floor, GYRO_HEADING, known_floors=known),
        "Map filtering": particle_filter(
            normal, b.plan, sxy, start.floor, n=200, seed=seed, known_floors=known
        ),
        "Zee": particle_filter(
            normal, b.plan, None, start.floor, n=2000, seed=seed, smooth=True, known_floors=known
        ),
        "Tap interpolation": tap_interpolation(normal, res.steps.t, b.graph),
    }
    traj_err = {k: v.errors(normal) for k, v in methods.items()}

    queries = Fingerprints.from_session(sims["heldout"].session)
    maps = {
        "Ours": Fingerprints.of_walk(res.radiomap),
        "Zee": methods["Zee"].radio_map(normal),
        "Manual (5 scans)": Fingerprints.from_session(sims["survey5"].session),
        "Manual (10 scans)": Fingerprints.from_session(sims["survey10"].session),
        "PDR I": methods["PDR I (compass)"].radio_map(normal),
    }
    per_method, tau_sweep = _maps_errors(maps, queries, tau)
    pool = _belief_pool(sims, b, params)
    belief_rows, belief_split = _belief_bins(pool, queries, eps, tau)
    return Simulated(
        walk_length_m=round(
            float(np.hypot(*np.diff(b.route_points("survey")[:, :2], axis=0).T).sum()), 1
        ),
        trajectory_error={k: _stats(v) for k, v in traj_err.items()},
        radio_maps=per_method,
        tau_sweep_sorensen_mean_m=tau_sweep,
        tau_dbm=tau,
        belief_bins=belief_rows,
        rp_error_by_belief=belief_split,
        survey_time=_survey_time(sims),
        ours_summary=res.summary(normal, b.graph),
        trajectory_error_samples=dict(traj_err),
        belief_scatter=tuple((rm.belief[rm.segment >= 0], e[rm.segment >= 0]) for rm, e in pool),
    )


def _maps_errors(maps: dict, queries, tau: float) -> tuple[dict[str, MapErrors], dict]:
    """Figs. 7–9: each map's errors under both metrics, and under Sørensen at every τ."""
    per_method = {
        name: MapErrors(len(rm), *(errors(localize(rm, queries, metric, tau=tau), queries)
                                   for metric in (Metric.EUCLIDEAN, Metric.SORENSEN)))
        for name, rm in maps.items()
    }  # fmt: skip
    tau_sweep = {
        name: {
            tau: errors(localize(rm, queries, Metric.SORENSEN, tau=float(tau)), queries).get(
                "mean_m"
            )
            for tau in TAUS
        }
        for name, rm in maps.items()
    }
    return per_method, tau_sweep


def _belief_pool(sims: dict, b, params: Params) -> list[tuple[RadioMap, np.ndarray]]:
    """Fig. 6: the normal and varied walks' scans, every one kept, with their placement errors."""
    pool: list[tuple[RadioMap, np.ndarray]] = []
    for w in ("normal", "varied"):
        s = sims[w].session
        pipe = Pipeline(s, b.graph, params.updated(**{"belief.threshold": 0.0}))
        placed = pipe.run().radiomap
        assert s.ground_truth is not None  # a simulated walk has its ground truth
        gx, gy, _ = s.ground_truth.at(placed.t)
        pool.append((placed, np.hypot(placed.x - gx, placed.y - gy)))
    return pool


def _belief_bins(
    pool, queries, eps: float, tau: float
) -> tuple[tuple[BeliefBin, ...], BeliefSplit]:
    """Fig. 6: a map of the points whose segment's belief reaches each bin, and the errors of
    the points at most and above the threshold ``eps``."""
    # a radio map from every reference point whose segment's belief reaches b: the threshold
    # trades coverage (more points) against placement quality
    belief_rows = []
    for lo in sorted({0, 5, 10, 18, 25, 40, eps}):
        parts, rp_err = [], []
        for pm, e in pool:
            m = (pm.segment >= 0) & (pm.belief >= lo)
            parts.append(Fingerprints(pm.x[m], pm.y[m], pm.floor[m], pm.bssids, pm.rss[m]))
            rp_err.append(e[m])
        fp = Fingerprints.merge(parts)
        errs = np.concatenate(rp_err)
        belief_rows.append(BeliefBin(
            f"≥ {lo:g}", len(fp), round(float(errs.mean()), 3) if errs.size else None,
            errors(localize(fp, queries, Metric.EUCLIDEAN, tau=tau), queries) if len(fp) else {},
        ))  # fmt: skip
    below = np.concatenate([e[(pm.segment >= 0) & (pm.belief <= eps)] for pm, e in pool])
    above = np.concatenate([e[(pm.segment >= 0) & (pm.belief > eps)] for pm, e in pool])
    belief_split = BeliefSplit(eps, _stats(below) | {"n": int(below.size)},
                               _stats(above) | {"n": int(above.size)})  # fmt: skip
    return tuple(belief_rows), belief_split


def _survey_time(sims: dict) -> dict[str, dict[str, float]]:
    """Table II: setup and data collection, minutes (the time model of the results page)."""
    survey = {}
    walk_min = sims["normal"].session.duration / 60.0
    survey["Proposed method"] = {"setup_min": SETUP_GRAPH_MIN, "collection_min": round(walk_min, 1)}
    survey["Zee"] = {"setup_min": SETUP_GRAPH_MIN, "collection_min": round(walk_min, 1)}
    for k in (5, 10):
        meta = sims[f"survey{k}"].session.metadata.extra
        survey[f"Manual ({k} scans)"] = {
            "setup_min": round(meta["reference_points"] * SETUP_PER_MANUAL_POINT_S / 60.0, 1),
            "collection_min": round(meta["survey_time_s"] / 60.0, 1),
        }
    return survey
