"""``workstation evaluate``'s body: the run and what it prints (its parser is in
:mod:`workstation.commands.evaluate`, which loads this only when the command runs)."""

from __future__ import annotations

import argparse
from pathlib import Path

from workstation.errors import WorkstationError
from workstation.evaluate import evaluate, evaluate_walks
from workstation.evaluate.report_walks import trust_lines
from workstation.evaluate.sigma_check import calibration_words, held_out_words
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.progress import Progress


def run(args: argparse.Namespace) -> int:
    params = Params.load(args.params) if args.params else Params()
    if args.walks:
        if not args.graph:
            raise WorkstationError("evaluate --walks needs --graph GRAPH")
        return _walks(args, params)
    if args.graph:
        raise WorkstationError("--graph is only used with --walks")
    if args.end:
        raise WorkstationError("--end is only used with --walks")

    shared = args.shared
    if shared is None:
        guess = Path(__file__).resolve().parents[3] / "shared" / "data"
        shared = guess if guess.is_dir() else None

    bar = Progress()
    res = evaluate(args.out, shared, args.seed, params, args.model, args.seeds, bar)
    bar.close()
    sim = res["simulated"]
    print(f"wrote {args.out}/results.md, results.json and figures ({args.model} simulator)")
    for k, v in sim["trajectory_error"].items():
        print(f"  trajectory error  {k:<24} mean {v['mean_m']:7.2f} m")
    for k, v in sim["radio_maps"].items():
        e = v["euclidean"]
        print(
            f"  1-NN on {k:<20} mean {e.get('mean_m', float('nan')):5.2f} m  "
            f"floor {100 * e['floor_accuracy']:5.1f} %  ({v['reference_points']} RPs)"
        )
    for r in res["robustness"]:
        print(
            f"  robustness {r['condition']:<22} {r['association']:<6} mean {r['mean_m']:6.2f} m  "
            f"lost {r['lost']}/{r['seeds']}"
        )
    for r in res["density"]:
        print(
            f"  density {r['radio_map']:<30} {r['reference_points']:7.1f} RPs  "
            f"mean {r['mean_m']:5.2f} m  with floor penalty {r['mean_with_floor_penalty_m']:5.2f} m"
        )
    if res["walks"]:
        print("  IPIN museum, leave one walk out:")
        _print_loo(res["walks"])
    return 0


def _walks(args, params) -> int:
    graph = LandmarkGraph.load(args.graph)

    bar = Progress()
    res = evaluate_walks(
        args.out, args.walks, graph, params, args.start, bar, args.queries_every, args.end
    )
    bar.close()
    print(f"wrote {args.out}/results.md, results.json and sigma_reliability.png")
    _print_loo(res.to_dict())
    return 0


def _print_loo(r: dict) -> None:
    t = r["tracking"]
    names = {
        "landmark_fix_match_rate": "landmark matched at the fix",
        "landmark_fix_match_rate_turned": "where the walk turned",
        "landmark_node_accuracy": "node",
        "floor_accuracy": "floor",
        "fix_error_mean_m": "error at the fixes (m)",
    }
    got = [f"{label} {t[k]}" for k, label in names.items() if t.get(k) is not None]
    print("    tracking: " + (", ".join(got) or "no ground-truth fixes to score"))
    for note in r.get("notes", []):
        print(f"    {note}")
    print(
        f"    walks quarantined (kept out of our maps): {r.get('walks_quarantined', 0)} of "
        f"{len(r['walks'])}; walks with a wrong start in our maps: {r.get('wrong_start_in_map', 0)}"
        + (
            f" (another start landmark nearby: {len(near)})"
            if (near := r.get("other_start_landmark_in_map"))
            else ""
        )
    )
    for line in trust_lines(r):
        print(f"    {line}")
    w = max((len(m["label"]) for m in r["loo"].values()), default=0)  # labels whole (#50)
    for kind, m in r["loo"].items():
        e = m["error_floor_right"]
        pl = (r.get("placement_by_kind") or {}).get(kind) or {}
        if not m["queries"]:
            print(f"    {m['label']:<{w}} no map: no walk gave it a reference point")
            continue
        print(
            f"    {m['label']:<{w}} floor {100 * m['floor_accuracy']:5.1f} %  "
            f"mean (floor right) {e.get('mean_m', float('nan')):5.2f} m  "
            f"with floor penalty {m['mean_with_floor_penalty_m']:6.2f} m  "
            f"covered {m.get('covered_mean_with_floor_penalty_m', float('nan')):6.2f} m  "
            f"({m['reference_points_per_map']:g} RPs/map, placed {pl.get('mean_m', '–')} m)"
        )
    sc = r.get("sigma_check") or {}
    if sc:
        print(
            f"    placement uncertainty σ: rank correlation with the true error "
            f"{sc['rank_correlation']} over {sc['scans']} scans; mean error per σ bin: "
            + ", ".join(f"{b['sigma_m']} m {b['mean_error_m']}" for b in sc["bins"])
        )
        if sc.get("held_out"):
            print(f"    {held_out_words(sc['held_out'])}")
        if sc.get("map_points", {}).get("scans"):
            print(f"    {calibration_words(sc['map_points'])}")
    pa = r["placement"]
    a, t, j = pa["accepted"], pa["trusted_segments"], pa["untrusted_closed"]
    print(
        f"    reference points: {a.get('n')} accepted placed {a.get('mean_m')} m; on trusted "
        f"segments {t.get('n')} at {t.get('mean_m')} m, untrusted closed {j.get('n')} at "
        f"{j.get('mean_m')} m"
    )
