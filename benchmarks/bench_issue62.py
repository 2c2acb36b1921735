"""Issue #62's table: every site1 floor in ../shared/data and the museum, the map as `merge`
builds it against the tap oracle and every row of every walk, the walks' verdicts against their
truth and σ's shares — with issue #63's lines from the same splits (bench_issue63)."""

from __future__ import annotations

from _common import SHARED_DATA, Table
from _common import with_bar as _bar

FLOORS = ("f1", "f2", "f3", "b1")


def floors() -> tuple[Table, Table]:
    """Issue #62's table: every site1 floor in shared and the museum, each a split (every 5th
    walk asks, start at the first fix, the graph from the map walks' taps, the defaults), the
    map as `merge` builds it (the walks placed together, walks/joint.py) against the tap oracle
    and every row of every walk, the walks' verdicts against their truth, σ's shares."""
    from bench_issue63 import floor_rows, kind_build_seconds, uji

    from workstation.evaluate.walks import ipin_museum, leave_one_out, walk_name
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks

    t = Table("Issue #62: every floor, the map as merge builds it (defaults)")
    m = Table("Issue #63: the default matcher on every floor, the museum and UJIIndoorLoc")
    for f in FLOORS:
        root = SHARED_DATA / f"microsoft-ilc2020-site1-{f}" / "path_data_files"
        files = sorted(root.glob("*.gz"))
        if not files:
            t.add(f"site1 {f.upper()}: {root} absent, left out", 0, "", "{:,.0f}")
            continue
        asks = set(sorted(walk_name(p) for p in files)[4::5])
        graph, _ = graph_from_walks([load_session(p) for p in files if walk_name(p) not in asks])
        r = leave_one_out(files, graph, queries_every=5)
        _floor_rows(t, f"site1 {f.upper()}", r, len(files) - len(asks), covered=False)
        floor_rows(m, f"site1 {f.upper()}", r, covered=False)
    museum = ipin_museum(SHARED_DATA)
    if museum is not None:
        r = leave_one_out(museum[0], museum[1], start="first-fix")
        _floor_rows(t, "museum (leave one out, covered)", r, len(museum[0]), covered=True)
        floor_rows(m, "museum (leave one out, covered)", r, covered=True)
    uji(m)
    kind_build_seconds(m)
    return t, m


def _floor_rows(t: Table, what: str, r, map_walks: int, covered: bool) -> None:
    """One floor's lines of issue #62's table."""
    k = ("covered_mean_with_floor_penalty_m" if covered else "mean_with_floor_penalty_m")
    ours, every, tap = (getattr(r.loo[n], k) for n in ("ours", "ours_unfiltered", "tap_oracle"))
    ok = ours <= 1.10 * tap and ours <= every
    _bar(t, f"{what}: merged / tap oracle (merged, every row, tap: {ours:.2f} / {every:.2f} / "
         f"{tap:.2f} m)", ours / tap, "×", ok, "≤ 1.10 and ≤ every row")  # fmt: skip
    v = r.verdicts
    wrong, good = len(v.in_map_placed_over_5m), len(v.held_placed_within_2m)
    _bar(t, f"{what}: map walks in the map placed > 5 m off ({wrong} of {map_walks})",
         100 * wrong / map_walks, "%", wrong <= 0.02 * map_walks, "≤ 2 %", "{:,.1f}")  # fmt: skip
    _bar(t, f"{what}: walks left out though placed ≤ 2 m ({good})", 100 * good / map_walks, "%",
         good <= 0.03 * map_walks, "≤ 3 %", "{:,.1f}")  # fmt: skip
    mp = r.sigma_check.map_points if r.sigma_check else None
    one, two = (mp.within_1_sigma, mp.within_2_sigma) if mp else (float("nan"), float("nan"))
    _bar(t, f"{what}: the map's points within 1σ / 2σ (2σ: {100 * two:.1f} %)", 100 * one, "%",
         0.60 <= one <= 0.75 and two >= 0.90, "60–75 % / ≥ 90 %", "{:,.1f}")  # fmt: skip
