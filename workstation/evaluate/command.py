"""``workstation evaluate``'s body: the run and what it prints (its parser is in
:mod:`workstation.commands.evaluate`, which loads this only when the command runs)."""

from __future__ import annotations

import argparse
from pathlib import Path

from workstation.errors import WorkstationError
from workstation.evaluate import evaluate, evaluate_walks
from workstation.evaluate.report_walks import trust_lines
from workstation.evaluate.sigma_check import SigmaCheck
from workstation.evaluate.walks import LooResult
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
    sim = res.simulated
    print(f"wrote {args.out}/results.md, results.json and figures ({args.model} simulator)")
    for k, v in sim.trajectory_error.items():
        print(f"  trajectory error  {k:<24} mean {v['mean_m']:7.2f} m")
    for k, m in sim.radio_maps.items():
        e = m.euclidean
        print(
            f"  1-NN on {k:<20} mean {e.get('mean_m', float('nan')):5.2f} m  "
            f"floor {100 * (e['floor_accuracy'] or 0.0):5.1f} %  ({m.reference_points} RPs)"
        )
    for r in res.robustness:
        print(
            f"  robustness {r.condition:<22} {r.association:<6} mean {r.mean_m:6.2f} m  "
            f"lost {r.lost}/{r.seeds}"
        )
    for d in res.density:
        print(
            f"  density {d.radio_map:<30} {d.reference_points:7.1f} RPs  "
            f"mean {d.mean_m:5.2f} m  with floor penalty {d.mean_with_floor_penalty_m:5.2f} m"
        )
    if res.walks:
        print("  IPIN museum, leave one walk out:")
        _print_loo(res.walks)
    return 0


def _walks(args, params) -> int:
    graph = LandmarkGraph.load(args.graph)

    bar = Progress()
    res = evaluate_walks(
        args.out, args.walks, graph, params, args.start, bar, args.queries_every, args.end
    )
    bar.close()
    print(f"wrote {args.out}/results.md, results.json and sigma_reliability.png")
    _print_loo(res)
    return 0


def _print_loo(res: LooResult) -> None:
    t = res.tracking
    names = {
        "landmark_fix_match_rate": "landmark matched at the fix",
        "landmark_fix_match_rate_turned": "where the walk turned",
        "landmark_node_accuracy": "node",
        "floor_accuracy": "floor",
        "fix_error_mean_m": "error at the fixes (m)",
    }
    got = [f"{label} {t[k]}" for k, label in names.items() if t.get(k) is not None]
    print("    tracking: " + (", ".join(got) or "no ground-truth fixes to score"))
    for note in res.notes:
        print(f"    {note}")
    near = res.other_start_landmark_in_map
    print(
        f"    walks quarantined (kept out of our maps): {res.walks_quarantined} of "
        f"{len(res.walks)}; walks with a wrong start in our maps: {res.wrong_start_in_map}"
        + (f" (another start landmark nearby: {len(near)})" if near else "")
    )
    for line in trust_lines(res):
        print(f"    {line}")
    w = max((len(m.label) for m in res.loo.values()), default=0)  # labels whole (#50)
    for kind, m in res.loo.items():
        e = m.error_floor_right
        pl = res.placement_by_kind.get(kind) or {}
        if not m.queries:
            print(f"    {m.label:<{w}} no map: no walk gave it a reference point")
            continue
        print(
            f"    {m.label:<{w}} floor {100 * m.floor_accuracy:5.1f} %  "
            f"mean (floor right) {e.get('mean_m', float('nan')):5.2f} m  "
            f"with floor penalty {m.mean_with_floor_penalty_m:6.2f} m  "
            f"covered {m.covered_mean_with_floor_penalty_m:6.2f} m  "
            f"({m.reference_points_per_map:g} RPs/map, placed {pl.get('mean_m', '–')} m)"
        )
    sc = res.sigma_check or SigmaCheck()
    if sc.scans is not None:
        print(
            f"    placement uncertainty σ: rank correlation with the true error "
            f"{sc.scans.rank_correlation} over {sc.scans.scans} scans; mean error per σ bin: "
            + ", ".join(f"{b.sigma_m} m {b.mean_error_m}" for b in sc.scans.bins)
        )
        if sc.held_out:
            print(f"    {sc.held_out.words()}")
        if sc.map_points is not None and sc.map_points.scans:
            print(f"    {sc.map_points.words()}")
    pa = res.placement
    a, tr, j = pa["accepted"], pa["trusted_segments"], pa["untrusted_closed"]
    print(
        f"    reference points: {a.get('n')} accepted placed {a.get('mean_m')} m; on trusted "
        f"segments {tr.get('n')} at {tr.get('mean_m')} m, untrusted closed {j.get('n')} at "
        f"{j.get('mean_m')} m"
    )
