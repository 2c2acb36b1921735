"""The paper's experiments, regenerated: ``workstation evaluate --out DIR``.

On the simulated two-floor office (dense ground truth) and on the real IPIN museum walks:
trajectory error CDF per method (Fig. 5), 1-NN error against segment belief (Fig. 6), floor
accuracy and mean 1-NN error per radio-map method and metric (Figs. 7–8), mean error against τ
(Fig. 9), survey time per method (Table II), and radio maps from some real walks localizing
another. Writes PNG figures, ``results.json`` and ``results.md``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ._atomic import atomic_write_text
from .baselines import Trajectory
from .baselines.particles import particle_filter
from .baselines.pdr import pdr
from .baselines.tap import tap_interpolation
from .localize import Fingerprints, Metric, errors, localize
from .params import Params
from .pipeline import Pipeline
from .sim import simulate
from .sim.building import office2f

# Table II time model (minutes), stated rather than measured: drawing a landmark graph or the
# walls from a floor plan takes about ten minutes (the paper's figure); a manual survey point
# is measured and marked in 25 s and each point needs its stationary scans (2 s a scan) and
# 8 s to move to it (the simulator's survey model).
SETUP_GRAPH_MIN = 10.0
SETUP_PER_MANUAL_POINT_S = 25.0
TAUS = tuple(range(-100, -55, 5))


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
    m = tr.segment >= 0
    return Trajectory(tr.t[m], tr.x[m], tr.y[m], tr.floor[m])


def simulated(seed: int = 1) -> dict[str, Any]:
    b = office2f()
    sims = {w: simulate(b, w, seed) for w in ("normal", "varied", "heldout", "survey5", "survey10")}
    normal = sims["normal"].session
    res = Pipeline(normal, b.graph).run()
    start = b.graph.node(res.track.start_node)
    sxy = (start.x, start.y)
    known = np.array(b.graph.floors)
    methods = {
        "Landmark graph (ours)": _ours_trajectory(res),
        "PDR I (compass)": pdr(normal, sxy, start.floor, "compass", known_floors=known),
        "PDR II (gyro)": pdr(normal, sxy, start.floor, "gyro", known_floors=known),
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
        "Ours": Fingerprints.from_radiomap(res.radiomap),
        "Zee": methods["Zee"].radio_map(normal),
        "Manual (5 scans)": Fingerprints.from_session(sims["survey5"].session),
        "Manual (10 scans)": Fingerprints.from_session(sims["survey10"].session),
        "PDR I": methods["PDR I (compass)"].radio_map(normal),
    }
    per_method = {}
    for name, rm in maps.items():
        per_method[name] = {"reference_points": len(rm)}
        for metric in Metric:
            per_method[name][metric.value] = errors(
                localize(rm, queries, metric, tau=-90.0), queries
            )
    tau_sweep = {
        name: {
            tau: errors(localize(rm, queries, Metric.SORENSEN, tau=float(tau)), queries).get(
                "mean_m"
            )
            for tau in TAUS
        }
        for name, rm in maps.items()
    }

    # Fig. 6: radio maps from segments of a given belief (normal + varied walks, all scans kept)
    pool = []
    for w in ("normal", "varied"):
        s = sims[w].session
        pipe = Pipeline(s, b.graph, Params().updated(**{"belief.threshold": 0.0}))
        r = pipe.run()
        rm = r.radiomap
        gx, gy, _ = s.ground_truth.at(rm.t)
        pool.append((rm, np.hypot(rm.x - gx, rm.y - gy)))
    # a radio map from every reference point whose segment's belief reaches b: the threshold
    # trades coverage (more points) against placement quality
    belief_rows = []
    for lo in (0, 5, 10, 15, 18, 25, 40):
        parts, rp_err = [], []
        for rm, e in pool:
            m = (rm.segment >= 0) & (rm.belief >= lo)
            parts.append(Fingerprints(rm.x[m], rm.y[m], rm.floor[m], rm.bssids, rm.rss[m]))
            rp_err.append(e[m])
        fp = Fingerprints.merge(parts)
        errs = np.concatenate(rp_err)
        row = {
            "belief": f"≥ {lo}",
            "reference_points": len(fp),
            "rp_error_mean_m": round(float(errs.mean()), 3) if errs.size else None,
        }
        if len(fp):
            row.update(errors(localize(fp, queries, Metric.EUCLIDEAN, tau=-90.0), queries))
        belief_rows.append(row)
    below = np.concatenate([e[(rm.segment >= 0) & (rm.belief < 15)] for rm, e in pool])
    above = np.concatenate([e[(rm.segment >= 0) & (rm.belief >= 15)] for rm, e in pool])
    belief_split = {
        "below_15": _stats(below) | {"n": int(below.size)},
        "at_least_15": _stats(above) | {"n": int(above.size)},
    }

    survey = {}
    walk_min = normal.duration / 60.0
    survey["Proposed method"] = {"setup_min": SETUP_GRAPH_MIN, "collection_min": round(walk_min, 1)}
    survey["Zee"] = {"setup_min": SETUP_GRAPH_MIN, "collection_min": round(walk_min, 1)}
    for k in (5, 10):
        meta = sims[f"survey{k}"].session.metadata
        survey[f"Manual ({k} scans)"] = {
            "setup_min": round(meta["reference_points"] * SETUP_PER_MANUAL_POINT_S / 60.0, 1),
            "collection_min": round(meta["survey_time_s"] / 60.0, 1),
        }
    return {
        "walk_length_m": round(
            float(np.hypot(*np.diff(b.route_points("survey")[:, :2], axis=0).T).sum()), 1
        ),
        "trajectory_error": {k: _stats(v) for k, v in traj_err.items()},
        "_trajectory_error_samples": {k: v for k, v in traj_err.items()},
        "radio_maps": per_method,
        "tau_sweep_sorensen_mean_m": tau_sweep,
        "belief_bins": belief_rows,
        "rp_error_by_belief": belief_split,
        "_belief_scatter": [(rm.belief[rm.segment >= 0], e[rm.segment >= 0]) for rm, e in pool],
        "survey_time": survey,
        "ours_summary": res.summary(normal, b.graph),
    }


def real_ipin(data: Path) -> dict[str, Any] | None:
    """Radio maps from all museum walks but one, 1-NN on the one left out (GT between POSI)."""
    from .graph import graph_from_tra
    from .pipeline.start import resolve_start
    from .session import load_session

    logs = sorted((data / "ipin2023-track3" / "logfiles").glob("*.txt"))
    tra = sorted((data / "ipin2023-track3" / "supplementary" / "trajectories").glob("*.tra"))
    if not logs or not tra:
        return None
    graph = graph_from_tra(tra)
    base = Params()  # the defaults: no per-building behaviour parameters
    walks = {}
    runs = []
    rp_err = []  # (belief, position error against the fixes interpolated in time) per walk
    for f in logs:
        s = load_session(f).in_frame(graph.frame)
        p = base.updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})
        r = Pipeline(s, graph, p).run()
        runs.append((r, s, graph))
        gt = s.ground_truth
        start = graph.node(r.track.start_node)
        rm = r.radiomap
        inside = (rm.segment >= 0) & (rm.t >= gt.t[0]) & (rm.t <= gt.t[-1])
        gx, gy, _ = gt.at(rm.t[inside])
        rp_err.append((rm.belief[inside], np.hypot(rm.x[inside] - gx, rm.y[inside] - gy)))
        walks[f.stem] = {
            "session": s,
            "summary": r.summary(s, graph),
            "Ours": Fingerprints.from_radiomap(r.radiomap, graph.frame),
            "Ours without the belief filter": Fingerprints.from_radiomap(
                r.radiomap, graph.frame, accepted_only=False
            ),
            "Tap interpolation (oracle)": tap_interpolation(s, r.steps.t).radio_map(s, graph.frame),
            "PDR I": pdr(
                s, (start.x, start.y), start.floor, "compass", known_floors=np.array(graph.floors)
            ).radio_map(s, graph.frame),
            "fixes": len(gt),
        }
    rows = []
    for name in ("Ours", "Ours without the belief filter", "Tap interpolation (oracle)", "PDR I"):
        res = []
        for q, w in walks.items():
            others = [v[name] for k, v in walks.items() if k != q and len(v[name])]
            rm = Fingerprints.merge(others)
            queries = Fingerprints.from_session(w["session"])
            res.append(
                errors(localize(rm, queries, Metric.EUCLIDEAN, tau=-90.0), queries)
                | {"reference_points": len(rm)}
            )
        means = [r["mean_m"] for r in res if "mean_m" in r]
        rows.append(
            {
                "method": name,
                "mean_of_walk_means_m": round(float(np.mean(means)), 3),
                "floor_accuracy": round(float(np.mean([r["floor_accuracy"] for r in res])), 4),
                "reference_points_per_map": int(np.mean([r["reference_points"] for r in res])),
            }
        )
    bel = np.concatenate([b for b, _ in rp_err]) if rp_err else np.empty(0)
    err = np.concatenate([e for _, e in rp_err]) if rp_err else np.empty(0)
    rp_by_belief = {
        "below_15": _stats(err[bel <= 15]) | {"n": int((bel <= 15).sum())},
        "above_15": _stats(err[bel > 15]) | {"n": int((bel > 15).sum())},
    }
    from .pipeline.metrics import pooled_fix_metrics

    pooled = pooled_fix_metrics(runs)
    return {
        "walks": len(walks),
        "leave_one_out": rows,
        "rp_error_by_belief": rp_by_belief,
        "pooled": pooled,
        "landmark_node_accuracy_pooled": pooled["landmark_node_accuracy"],
        "floor_accuracy_pooled": pooled["floor_accuracy"],
        "per_walk": {
            name: {
                key: w["summary"].get(key)
                for key in (
                    "landmark_node_accuracy",
                    "landmark_fix_match_rate",
                    "floor_accuracy",
                    "fix_error_mean_m",
                    "trajectory_error_mean_m",
                    "reference_points",
                    "reference_point_error_mean_m",
                )
            }
            for name, w in walks.items()
        },
    }


def _figures(sim: dict, out: Path) -> dict[str, str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figs = {}
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, e in sim["_trajectory_error_samples"].items():
        e = np.sort(e)
        ax.plot(e, np.arange(1, e.size + 1) / e.size, label=f"{name} ({e.mean():.2f} m)")
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlabel("trajectory error (m)")
    ax.set_ylabel("CDF")
    ax.set_title("Fig. 5 — trajectory error per method (simulated office, normal walk)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    figs["fig5_trajectory_cdf"] = "fig5_trajectory_cdf.png"
    fig.tight_layout()
    fig.savefig(out / figs["fig5_trajectory_cdf"], dpi=110)
    plt.close(fig)

    rows = [r for r in sim["belief_bins"] if "mean_m" in r]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
    for bel, e in sim["_belief_scatter"]:
        ax1.scatter(np.minimum(bel, 150), e, s=8, alpha=0.6)
    ax1.axvline(15, color="r", lw=1, label="ε_S = 15")
    ax1.set_xlabel("belief of the segment (capped at 150)")
    ax1.set_ylabel("reference point position error (m)")
    ax1.legend(fontsize=7)
    ax2.plot([r["belief"] for r in rows], [r["mean_m"] for r in rows], marker="o")
    ax2.set_xlabel("radio map from segments with belief")
    ax2.set_ylabel("mean 1-NN error (m)")
    fig.suptitle("Fig. 6 — belief vs reference-point error and 1-NN error (normal + varied walks)")
    figs["fig6_belief"] = "fig6_belief.png"
    fig.tight_layout()
    fig.savefig(out / figs["fig6_belief"], dpi=110)
    plt.close(fig)

    names = list(sim["radio_maps"])
    for key, label, fname in (
        ("floor_accuracy", "floor accuracy (%)", "fig7_floor_accuracy"),
        ("mean_m", "mean 1-NN error (m)", "fig8_mean_error"),
    ):
        fig, ax = plt.subplots(figsize=(6, 3.5))
        xs = np.arange(len(names))
        for i, metric in enumerate(Metric):
            vals = [sim["radio_maps"][n][metric.value].get(key) or 0 for n in names]
            if key == "floor_accuracy":
                vals = [100 * v for v in vals]
            ax.bar(xs + (i - 0.5) * 0.38, vals, 0.38, label=metric.value)
        ax.set_xticks(xs, names, fontsize=7)
        ax.set_ylabel(label)
        ax.set_title(f"Fig. {7 if key == 'floor_accuracy' else 8} — {label}, τ = −90 dBm")
        ax.legend(fontsize=7)
        figs[fname] = f"{fname}.png"
        fig.tight_layout()
        fig.savefig(out / figs[fname], dpi=110)
        plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 3.5))
    for name, sweep in sim["tau_sweep_sorensen_mean_m"].items():
        ax.plot(
            list(sweep),
            [v if v is not None else np.nan for v in sweep.values()],
            marker="o",
            label=name,
        )
    ax.set_xlabel("τ (dBm)")
    ax.set_ylabel("mean 1-NN error (m), Sørensen")
    ax.set_title("Fig. 9 — effect of the RSS threshold τ")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    figs["fig9_tau"] = "fig9_tau.png"
    fig.tight_layout()
    fig.savefig(out / figs["fig9_tau"], dpi=110)
    plt.close(fig)
    return figs


def _markdown(sim: dict, real: dict | None, figs: dict[str, str]) -> str:
    te = sim["trajectory_error"]
    ours = te["Landmark graph (ours)"]["mean_m"]
    L = [
        "# Results — the paper's experiments, regenerated",
        "",
        "Produced by `workstation evaluate`. Simulated: the bundled two-floor office "
        f"({sim['walk_length_m']} m route, seed 1); real: the IPIN 2023 museum walks in ../shared/data.",
        "",
        "## Trajectory error per method (Fig. 5)",
        "",
        f"![Fig. 5]({figs['fig5_trajectory_cdf']})",
        "",
        "| method | mean (m) | median (m) | p90 (m) |",
        "|---|---|---|---|",
    ]
    L += [f"| {k} | {v['mean_m']} | {v['median_m']} | {v['p90_m']} |" for k, v in te.items()]
    L += [
        "",
        f"The landmark-graph PDR reaches a mean error of {ours} m against the paper's 0.71 m; as in the "
        "paper it is far ahead of PDR I/II and map filtering. Tap interpolation uses the true landmark "
        "times and is an upper bound, not a competitor. Zee is our re-implementation (a particle filter "
        "from an unknown start over the walls, 2,000 particles, backward smoothing of the largest family): "
        "the simulated office is a symmetric ring of corridors and it often settles on a shifted copy of "
        "the path, so it does worse here than in the paper (where only its radio map is compared).",
        "",
        "## 1-NN error vs belief (Fig. 6)",
        "",
        f"![Fig. 6]({figs['fig6_belief']})",
        "",
        "| radio map from belief | RPs | RP position error (m) | mean 1-NN error (m) | floor accuracy |",
        "|---|---|---|---|---|",
    ]
    L += [
        f"| {r['belief']} | {r['reference_points']} | {r.get('rp_error_mean_m')} | {r.get('mean_m', '–')} | {r.get('floor_accuracy', '–')} |"
        for r in sim["belief_bins"]
    ]
    sp = sim["rp_error_by_belief"]
    L += [
        "",
        f"Reference points on segments with belief below ε_S = 15 are placed with a mean error of "
        f"{sp['below_15'].get('mean_m')} m ({sp['below_15']['n']} points), those at or above it with "
        f"{sp['at_least_15'].get('mean_m')} m ({sp['at_least_15']['n']} points). The paper shows the same "
        "(1-NN much better with bel > 18 than with bel < 10); raising the threshold further only removes coverage.",
        "",
        "## Radio-map methods (Figs. 7–8), τ = −90 dBm, queries: the held-out walk",
        "",
        f"![Fig. 7]({figs['fig7_floor_accuracy']}) ![Fig. 8]({figs['fig8_mean_error']})",
        "",
        "| radio map | RPs | floor acc. Euclidean | mean Euclidean (m) | floor acc. Sørensen | mean Sørensen (m) |",
        "|---|---|---|---|---|---|",
    ]
    for name, r in sim["radio_maps"].items():
        e, s = r["euclidean"], r["sorensen"]
        L.append(
            f"| {name} | {r['reference_points']} | {e['floor_accuracy']} | {e.get('mean_m')} | {s['floor_accuracy']} | {s.get('mean_m')} |"
        )
    rm = sim["radio_maps"]
    L += [
        "",
        f"The paper has ours ≈ 1.5 m, Zee ≈ 2.3 m, manual ≈ 2.2 m. Here ours gives {rm['Ours']['euclidean'].get('mean_m')} m, "
        f"Zee {rm['Zee']['euclidean'].get('mean_m')} m and the manual 10-scan survey {rm['Manual (10 scans)']['euclidean'].get('mean_m')} m: "
        "the simulated walk scans only every 2–4 s (the paper's phone gave 609 reference points on a 362 m path), "
        "so our map is sparser than the paper's and the dense manual grid is hard to beat in simulation.",
        "",
        "## Effect of τ (Fig. 9), Sørensen",
        "",
        f"![Fig. 9]({figs['fig9_tau']})",
        "",
        "| τ (dBm) | " + " | ".join(sim["tau_sweep_sorensen_mean_m"]) + " |",
        "|---" * (1 + len(sim["tau_sweep_sorensen_mean_m"])) + "|",
    ]
    for tau in TAUS:
        L.append(
            f"| {tau} | "
            + " | ".join(str(v.get(tau)) for v in sim["tau_sweep_sorensen_mean_m"].values())
            + " |"
        )
    L += [
        "",
        "The paper finds the best τ at −80 dBm; see the table for where the minimum falls here.",
        "",
        "## Survey time (Table II)",
        "",
        "| method | setup (min) | data collection (min) |",
        "|---|---|---|",
    ]
    L += [
        f"| {k} | {v['setup_min']} | {v['collection_min']} |" for k, v in sim["survey_time"].items()
    ]
    L += [
        "",
        f"Time model (stated, not measured): {SETUP_GRAPH_MIN:g} min to draw the landmark graph or the walls, "
        f"{SETUP_PER_MANUAL_POINT_S:g} s to measure and mark each manual point, 2 s a stationary scan and 8 s to move "
        "between points; walks take their simulated duration. The paper: ~90 + 50/100 min manual, ~10 + 10 min ours.",
    ]
    if real:
        L += [
            "",
            f"## Real walks (IPIN 2023 museum, {real['walks']} walks, leave one out)",
            "",
            "Tracking with the default parameters, start at the first fix, pooled over the POSI fixes: "
            + ", ".join(f"{k} {v}" for k, v in real["pooled"].items() if k not in ("walks",))
            + ". (landmark_fix_match_rate: of the fixes on a landmark with a detection rule, that "
            "landmark matched within ±3 s; fix errors on the trajectory the radio map is placed on, "
            "forward_* on the forward trajectory.)",
            "",
            "| radio map from the other walks | mean 1-NN error (m) | floor accuracy | RPs per map |",
            "|---|---|---|---|",
        ]
        L += [
            f"| {r['method']} | {r['mean_of_walk_means_m']} | {r['floor_accuracy']} | {r['reference_points_per_map']} |"
            for r in real["leave_one_out"]
        ]
        rb = real["rp_error_by_belief"]
        L += [
            "",
            "Each walk is localized on the radio map of the nine others (ground truth interpolated between "
            "its POSI fixes); tap interpolation uses the true POSI times and is an oracle.",
            "",
            f"Reference points placed against the POSI fixes interpolated in time: belief ≤ 15 "
            f"{rb['below_15'].get('mean_m')} m ({rb['below_15']['n']} points), belief > 15 "
            f"{rb['above_15'].get('mean_m')} m ({rb['above_15']['n']} points). These walkers walk steadily "
            "and stop at every landmark to tap it, so low belief here comes from the stops rather than from "
            "badly placed points: the filtered map is smaller and misses parts of some floors, which costs "
            "floor accuracy, and the unfiltered row is the better map on such walks (a lower ε_S in the panel).",
        ]
    return "\n".join(L) + "\n"


def evaluate(
    out: str | Path, shared_data: str | Path | None = None, seed: int = 1
) -> dict[str, Any]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    sim = simulated(seed)
    real = real_ipin(Path(shared_data)) if shared_data and Path(shared_data).is_dir() else None
    figs = _figures(sim, out)
    result = {k: v for k, v in sim.items() if not k.startswith("_")}
    result = {"simulated": result, "real_ipin": real}
    atomic_write_text(
        out / "results.json", json.dumps(result, indent=2, default=_json_default) + "\n"
    )
    atomic_write_text(out / "results.md", _markdown(sim, real, figs))
    return result


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)
