"""The two real buildings against the bars of issues #28 (short mall walks), #29 (the radio
map) and #49 (trust: the map as merge builds it, walks' verdicts against their truth, σ), with
the default parameters: every "Done when" figure in one table, each beside its bar
and marked ``ok`` or ``NOT MET``. Mall F1 (../shared/data/microsoft-ilc2020-site1-f1, 106
walks, the graph from their taps as `graph from-waypoints` builds it) and the IPIN museum (10
walks, the graph from the .tra files); each part is left out, said so, when its data is absent.
Takes about five minutes on two cores."""

from __future__ import annotations

import time

import numpy as np
from _common import SHARED_DATA, Table, median_of
from _common import with_bar as _bar

MALL = SHARED_DATA / "microsoft-ilc2020-site1-f1" / "path_data_files"


def _mall(t: Table) -> None:
    from workstation.evaluate.walks import leave_one_out
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.heading import estimate_heading
    from workstation.pipeline.reach import forget_shared
    from workstation.pipeline.start import start_time
    from workstation.pipeline.steps import detect_steps
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    files = sorted(MALL.glob("*.gz"))
    graph, _ = graph_from_walks([load_session(f) for f in files])
    t.add(
        "mall F1: walks / landmarks from their taps",
        len(files),
        f"walks, {len(graph.nodes)} landmarks",
        "{:,.0f}",
    )

    # issue #28, --start first-fix: the tracker, and the walks that give reference points
    split = leave_one_out(files, graph, start="first-fix", queries_every=5)
    tr = split.tracking
    _bar(t, "#28 first-fix: right landmark matched at the fix", tr["landmark_fix_match_rate"], "",
         tr["landmark_fix_match_rate"] >= 0.90, "≥ 0.90")  # fmt: skip
    t.add("    … where the walk turned there", tr["landmark_fix_match_rate_turned"], "", "{:,.3f}")
    # the most the paper's rules allow: every fix where the walk turned matched, and of those
    # on a turn landmark it went straight through, only the ones a detection matches today
    ruled, straight = tr["landmark_rule_fixes"], tr["landmark_rule_fixes_passed_straight"]
    turned_ok = tr["landmark_fix_match_rate_turned"] * (ruled - straight)
    straight_ok = tr["landmark_fix_match_rate"] * ruled - turned_ok
    t.add(
        f"    … at most, every turned fix matched (passed straight: {straight:.0f} of {ruled:.0f})",
        (ruled - straight + straight_ok) / ruled,
        "",
        "{:,.3f}",
    )
    _bar(t, "#28 first-fix: error at the fixes, mean", tr["fix_error_mean_m"], "m",
         tr["fix_error_mean_m"] <= 1.5, "≤ 1.5 m")  # fmt: skip
    pw = split.per_walk.values()
    gave = sum(1 for w in pw if w.in_map)
    _bar(t, "#28 first-fix: walks giving reference points (in the map)", 100 * gave / len(files),
         "%", gave >= 0.95 * len(files), "≥ 95 %", "{:,.1f}")  # fmt: skip
    _bar(t, "#28 first-fix: walks with a wrong start in the map", split.wrong_start_in_map, "",
         split.wrong_start_in_map == 0, "0", "{:,.0f}")  # fmt: skip
    # beside the bars, not instead: every walk also given its end, as a surveyor fixes a walk
    # that matched nothing (the landmark at its last tap: one more ground-truth point per walk)
    ended = leave_one_out(files, graph, start="first-fix", queries_every=5, end="last-fix")
    pw_e = ended.per_walk.values()
    gave_e = sum(1 for w in pw_e if w.in_map)
    em = {k: v.mean_with_floor_penalty_m for k, v in ended.loo.items()}
    t.add("    every end given too: error at the fixes / walks in the map",
          ended.tracking["fix_error_mean_m"], f"m / {gave_e} of {len(files)}", "{:,.3f}")  # fmt: skip
    t.add("    every end given too: ours / unfiltered / tap / waypoint", em["ours"],
          f"m / {em['ours_unfiltered']:.3f} / {em['tap_oracle']:.3f} / {em['waypoint_pdr']:.3f} m",
          "{:,.3f}")  # fmt: skip

    # … and only the walks the defaults quarantined given their end: what a surveyor does with
    # campaign.md's "needs the surveyor" list (its remedy for a walk that matched nothing)
    held = [n for n, w in split.per_walk.items() if w.quarantine]
    fixed = leave_one_out(files, graph, start="first-fix", queries_every=5, end="last-fix",
                          end_for=held)  # fmt: skip
    fm = {k: v.mean_with_floor_penalty_m for k, v in fixed.loo.items()}
    t.add(f"    the {len(held)} quarantined walks given their end: ours / unfiltered / tap / waypoint",
          fm["ours"], f"m / {fm['ours_unfiltered']:.3f} / {fm['tap_oracle']:.3f} / "
          f"{fm['waypoint_pdr']:.3f} m ({fixed.walks_quarantined} still quarantined)",
          "{:,.3f}")  # fmt: skip

    # issue #29 on the same split: the map against the baselines, the placement, σ
    m = {k: v.mean_with_floor_penalty_m for k, v in split.loo.items()}
    ours, tap, way, unf = m["ours"], m["tap_oracle"], m["waypoint_pdr"], m["ours_unfiltered"]
    _bar(
        t,
        "#29 split: ours / tap oracle (the default matcher, floor penalty)",
        ours / tap,
        "×",
        ours <= 1.10 * tap,
        "≤ 1.10",
    )
    _bar(t, "#29 split: ours − waypoint-anchored baseline", ours - way, "m", ours <= way, "≤ 0")
    _bar(t, "#29 split: ours − ours unfiltered", ours - unf, "m", ours <= unf, "≤ 0")
    t.add(
        "    ours / unfiltered / tap / waypoint",
        ours,
        f"m / {unf:.3f} / {tap:.3f} / {way:.3f} m",
        "{:,.3f}",
    )
    # the issue's split is one of five rotations (every 5th walk from the 1st … 5th): their
    # mean says whether a figure on it is luck (docs/decisions.md, "Judge a map on five splits")
    kinds = ("ours", "ours_unfiltered", "tap_oracle", "waypoint_pdr")
    rot = [split] + [leave_one_out(files, graph, start="first-fix", queries_every=5,
                                   split_offset=k) for k in range(4)]  # fmt: skip
    five = [np.mean([r.loo[k].mean_with_floor_penalty_m for r in rot]) for k in kinds]
    t.add("    five splits, mean: ours / unfiltered / tap / waypoint", float(five[0]),
          f"m / {five[1]:.3f} / {five[2]:.3f} / {five[3]:.3f} m", "{:,.3f}")  # fmt: skip
    # … and each split's quarantined walks given their end, as the surveyor fixes them
    rot_fixed = [fixed] + [
        leave_one_out(files, graph, start="first-fix", queries_every=5, split_offset=k,
                      end="last-fix", end_for=[n for n, w in r.per_walk.items() if w.quarantine])
        for k, r in enumerate(rot[1:])
    ]  # fmt: skip
    five_f = [np.mean([r.loo[k].mean_with_floor_penalty_m for r in rot_fixed]) for k in kinds]
    t.add("    five splits, the quarantined walks given their end", float(five_f[0]),
          f"m / {five_f[1]:.3f} / {five_f[2]:.3f} / {five_f[3]:.3f} m", "{:,.3f}")  # fmt: skip
    placed = split.placement_by_kind["ours"]["mean_m"]
    _bar(t, "#29 split: placement of our points, mean", placed, "m", placed <= 1.0, "≤ 1.0 m")
    _trust(t, "split", split, len(files))
    sc = split.sigma_check
    rho = sc.scans.rank_correlation if sc and sc.scans else float("nan")
    _bar(t, "#29 split: σ rank correlation with the placement error", rho, "", rho >= 0.5, "≥ 0.5")
    h = sc.held_out if sc else None
    if h:  # σ's constants chosen on a random half of the walks, the figure on the other half
        lo = h.rank_correlation_min
        _bar(t, "#29 split: … on walks σ was not chosen on, mean", h.rank_correlation_mean, "",
             h.rank_correlation_mean >= 0.5, "≥ 0.5")  # fmt: skip
        t.add("    at worst (of the halvings)", lo, "", "{:,.3f}")

    # issue #28, the start inferred by the campaign's walks together
    tick = time.perf_counter()
    inf = leave_one_out(files, graph, start="infer", queries_every=5)
    sec = time.perf_counter() - tick
    right = sum(1 for w in inf.per_walk.values() if w.start_same_place)
    _bar(t, "#28 start inferred: walks started at the right place", 100 * right / len(files), "%",
         right >= 0.9 * len(files), "≥ 90 %", "{:,.1f}")  # fmt: skip
    _bar(t, "#28 start inferred: walks with a wrong start in the map", inf.wrong_start_in_map, "",
         inf.wrong_start_in_map == 0, "0", "{:,.0f}")  # fmt: skip
    t.add("    walks quarantined (start inferred)", inf.walks_quarantined, "", "{:,.0f}")
    t.add("    evaluate, split, start inferred (one run)", sec, "s", "{:,.1f}")
    # the same surveyor's walks, one after another: a certain walk hands its end to the next
    given = {f.name.split(".")[0] for f in sorted(files)[::2]}
    half = leave_one_out(files, graph, start="infer", queries_every=5, start_for=given)
    rest = [w for n, w in half.per_walk.items() if n not in given]
    sure = sum(1 for w in rest if w.start_same_place and not w.quarantine)
    handed = sum(1 for w in rest if w.start_after and not w.quarantine)
    t.add("    every 2nd walk's start given: the others' start right and in the map", sure,
          f"of {len(rest)} ({handed} handed on by the walk before)", "{:,.0f}")  # fmt: skip
    _bar(t, "#28 … of them, with a wrong start in the map", half.wrong_start_in_map, "",
         half.wrong_start_in_map == 0, "0", "{:,.0f}")  # fmt: skip
    ranked, first_right, among = _hints(files, graph, half.per_walk)
    t.add("    … the map's hint on those still ambiguous: the right start ranked first",
          first_right, f"of {ranked} (among those ranked: {among})", "{:,.0f}")  # fmt: skip

    # start times (never more than 2 s after the first step) and speed with the start inferred
    p = Params().updated(**{"pdr.start_node": None})
    late, speeds, first = [], [], []
    for f in files:
        s = load_session(f).in_frame(graph.frame)
        steps = detect_steps(s.accelerometer, p.steps)
        if len(steps):
            st = start_time(steps, p.pdr, estimate_heading(s, p.heading))
            late.append(st.t - steps.t[0])
        if 20.0 <= s.duration <= 40.0 and len(speeds) < 8:  # the first eight such walks
            # a walk of a campaign: the building's routes were searched for an earlier walk
            Pipeline(s, graph, p).run()
            sec, _ = median_of(lambda s=s: Pipeline(s, graph, p).run(), 3)
            speeds.append(s.duration / sec)
            # the first walk on a graph searches the routes from every landmark first
            sec, _ = median_of(lambda s=s: (forget_shared(), Pipeline(s, graph, p).run()), 3)
            first.append(s.duration / sec)
    late.sort(reverse=True)
    _bar(
        t,
        "#28 start time − first step, the worst walk",
        late[0],
        "s",
        late[0] <= 2.0,
        "≤ 2 s",
        "{:,.2f}",
    )
    t.add(
        "    the next four",
        late[1],
        "s, " + ", ".join(f"{x:.2f}" for x in late[2:5]) + " s",
        "{:,.2f}",
    )
    _bar(t, f"#28 speed, {len(speeds)} walks of 20–40 s, start inferred (median)",
         float(np.median(speeds)), "× real time", float(np.median(speeds)) >= 300, "≥ 300×", "{:,.0f}")  # fmt: skip
    t.add("    the slowest of them", float(np.min(speeds)), "× real time", "{:,.0f}")
    t.add(
        "    the first walk on the graph (median)",
        float(np.median(first)),
        "× real time",
        "{:,.0f}",
    )
    tick = time.perf_counter()
    loo = leave_one_out(files, graph, start="first-fix")
    sec = time.perf_counter() - tick
    m = [loo.loo[k].mean_with_floor_penalty_m for k in kinds]
    t.add("#29 leave one out: ours / unfiltered / tap / waypoint", m[0],
          f"m / {m[1]:.3f} / {m[2]:.3f} / {m[3]:.3f} m", "{:,.3f}")  # fmt: skip
    _bar(t, "#49 leave one out: the merged map / tap oracle", m[0] / m[2], "×", m[0] <= 1.10 * m[2],
         "≤ 1.10")  # fmt: skip
    _bar(t, "#49 leave one out: the merged map − every row", m[0] - m[1], "m", m[0] <= m[1], "≤ 0")
    _trust(t, "leave one out", loo, len(files))
    _bar(
        t,
        "#28 evaluate --walks, leave one out, 106 walks (one run)",
        sec,
        "s",
        sec <= 60,
        "≤ 60 s",
        "{:,.1f}",
    )


def _trust(t: Table, what: str, r, walks: int) -> None:
    """Issue #49's lines on one evaluation (``r``: a LooResult): the walks' verdicts against
    their truth and σ's shares over the points the map holds."""
    v = r.verdicts
    wrong, good = len(v.in_map_placed_over_5m), len(v.held_placed_within_2m)
    _bar(t, f"#49 {what}: walks in the map placed > 5 m off", 100 * wrong / walks, "%",
         wrong <= 0.02 * walks, "≤ 2 %", "{:,.1f}")  # fmt: skip
    t.add("    … which", wrong, ", ".join(n[:10] for n in v.in_map_placed_over_5m) or "–",
          "{:,.0f}")  # fmt: skip
    _bar(t, f"#49 {what}: walks kept out though placed within 2 m", 100 * good / walks, "%",
         good <= 0.03 * walks, "≤ 3 %", "{:,.1f}")  # fmt: skip
    t.add("    walks kept out, by reason", v.held, str(v.held_by_reason), "{:,.0f}")
    _sigma_shares(t, f"mall {what}", r)


def _sigma_shares(t: Table, what: str, r) -> None:
    mp = r.sigma_check.map_points if r.sigma_check else None
    one, two = (mp.within_1_sigma, mp.within_2_sigma) if mp else (float("nan"), float("nan"))
    _bar(t, f"#49 {what}: the map's points within 1σ of the truth", 100 * one, "%",
         0.60 <= one <= 0.75, "60–75 %", "{:,.1f}")  # fmt: skip
    _bar(t, f"#49 {what}: … within 2σ", 100 * two, "%", two >= 0.90, "≥ 90 %", "{:,.1f}")


def _hints(files, graph, per_walk: dict) -> tuple[int, int, int]:
    """The surveyor's hint (start_by_map.py) as a campaign gives it: every second walk's start
    given (its first tap's landmark) makes the building's map; each other walk whose start is
    still ambiguous after the handover (``per_walk``: evaluate's rows, walk_chain.py) has its
    candidate starts ranked on it — within the reach it was searched in, where it was. How
    many were ranked, on how many
    the first is at the right place (as the start inference counts places), and on how many the
    right place is among the ranked at all."""
    from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.confidence import ALTERNATIVE_START_M
    from workstation.pipeline.start import resolve_start
    from workstation.session import load_session
    from workstation.walks.start_by_map import rank_by_map

    pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}

    def same(a: str, b: str) -> bool:
        (ax, ay, af), (bx, by, bf) = pos[a], pos[b]
        return af == bf and float(np.hypot(ax - bx, ay - by)) <= ALTERNATIVE_START_M

    maps = []
    for f in files[::2]:
        s = load_session(f)
        r = Pipeline(
            s, graph, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})
        ).run()
        if not r.summary(s, graph).quarantined:
            maps.append(Fingerprints.of_walk(r.radiomap, graph.frame))
    index = RadioMapIndex(Fingerprints.merge(maps), Params().localize.tau_dbm)
    ranked = first = among = 0
    for f in files[1::2]:
        w = per_walk[f.name.split(".")[0]]
        if "start_ambiguous" not in w.quarantine:
            continue
        s = load_session(f)
        pipe = Pipeline(s, graph, Params())
        pipe.start_within = w.start_after.region if w.start_after else None
        r = pipe.run()
        cands = [n for n, _ in r.track.start.candidates]
        got = rank_by_map(s, graph, Params(), cands, index, pipe.start_within)
        right = resolve_start("first-fix", s, graph)
        order = [c[0] for c in got.ranked if c[1] == c[1]]
        ranked += 1
        first += bool(order) and same(order[0], right)
        among += any(same(n, right) for n in order)
    return ranked, first, among


def _museum(t: Table) -> None:
    from workstation.evaluate.walks import ipin_museum, leave_one_out

    museum = ipin_museum(SHARED_DATA)
    if museum is None:
        t.add("museum: ../shared/data/ipin2023-track3 absent, left out", 0, "", "{:,.0f}")
        return
    logs, graph = museum
    r = leave_one_out(logs, graph, start="first-fix")
    tr = r.tracking
    t.add("museum: landmark node / matched at the fix / error at the fixes", tr["landmark_node_accuracy"],
          f"/ {tr['landmark_fix_match_rate']:.3f} / {tr['fix_error_mean_m']:.3f} m", "{:,.3f}")  # fmt: skip
    c = {k: v.covered_mean_with_floor_penalty_m for k, v in r.loo.items()}
    ours, unf, tap = c["ours"], c["ours_unfiltered"], c["tap_oracle"]
    _bar(t, "#29 museum covered queries: ours − unfiltered", ours - unf, "m", ours <= unf, "≤ 0")
    _bar(t, "#29 museum covered queries: ours − tap oracle", ours - tap, "m", ours <= tap, "≤ 0")
    _bar(t, "#49 museum covered: ours ≤ unfiltered ≤ tap oracle", ours, "m",
         ours <= unf <= tap, "holds")  # fmt: skip
    _sigma_shares(t, "museum leave one out", r)
    v = r.verdicts
    t.add("    museum walks in the map placed > 5 m off / kept out though within 2 m",
          len(v.in_map_placed_over_5m), f"/ {len(v.held_placed_within_2m)}", "{:,.0f}")  # fmt: skip
    t.add("    ours / unfiltered / tap (covered)", ours, f"m / {unf:.3f} / {tap:.3f} m", "{:,.3f}")
    t.add(
        "    all queries, floor penalty: ours",
        r.loo["ours"].mean_with_floor_penalty_m,
        "m",
        "{:,.3f}",
    )
    # the same walks on the graph `graph from-waypoints` draws from their own taps: the
    # builder of issue #28 item 2 on a second building (no .tra drawn by hand)
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    taps, _ = graph_from_walks([load_session(p) for p in logs])
    r = leave_one_out(logs, taps, start="first-fix")
    tr = r.tracking
    t.add("museum, graph from its taps: node / matched at the fix / error at the fixes",
          tr["landmark_node_accuracy"],
          f"/ {tr['landmark_fix_match_rate']:.3f} / {tr['fix_error_mean_m']:.3f} m", "{:,.3f}")  # fmt: skip
    c = {k: v.covered_mean_with_floor_penalty_m for k, v in r.loo.items()}
    t.add("    ours / unfiltered / tap (covered)", c["ours"],
          f"m / {c['ours_unfiltered']:.3f} / {c['tap_oracle']:.3f} m", "{:,.3f}")  # fmt: skip


def run() -> Table:
    t = Table("Issues #28, #29 and #49: the real buildings against their bars (defaults)")
    if MALL.is_dir():
        _mall(t)
    else:
        t.add(f"mall F1: {MALL} absent, left out", 0, "", "{:,.0f}")
    _museum(t)
    return t


def tables() -> list[Table]:
    """Issue #62's and #63's tables of every floor first, then the bars of the issues before."""
    from bench_issue62 import floors

    return [*floors(), run()]


if __name__ == "__main__":
    for tab in tables():
        tab.print()
