"""Issue #63's lines: on each floor the default matcher on our merged map against the paper's
1-NN and the tap oracle (same matcher, and 1-NN), from the same splits as issue #62's table
(bench_issue62.floors), and UJIIndoorLoc with the default."""

from __future__ import annotations

from _common import SHARED_DATA, Table, with_bar


def _bar(t: Table, what: str, value: float, ok: bool, bar: str) -> None:
    with_bar(t, what, value, "×", ok, bar)  # a ratio


def floor_rows(t: Table, what: str, r, covered: bool) -> None:
    """One floor's lines: the default ÷ the paper's 1-NN on our map, ÷ the tap oracle under
    1-NN and under the same matcher (``r.matchers``, evaluate/map_kinds.score_matchers)."""
    from workstation.fingerprints.matchers import DEFAULT, PAPER

    k = "covered_mean_with_floor_penalty_m" if covered else "mean_with_floor_penalty_m"
    d, p = r.matchers[DEFAULT], r.matchers[PAPER]
    ours, ours1, tap, tap1 = (getattr(x, k) for x in (d["ours"], p["ours"], d["tap_oracle"],
                                                       p["tap_oracle"]))  # fmt: skip
    _bar(t, f"{what}: default on our map ÷ 1-NN on it ({ours:.2f} / {ours1:.2f} m)", ours / ours1,
         ours <= 0.85 * ours1, "≤ 0.85")  # fmt: skip
    _bar(t, f"{what}: default ÷ tap oracle with 1-NN ({tap1:.2f} m)", ours / tap1,
         ours <= 0.90 * tap1, "≤ 0.90")  # fmt: skip
    _bar(t, f"{what}: ours ÷ tap oracle, same matcher ({tap:.2f} m)", ours / tap,
         ours <= 1.05 * tap, "≤ 1.05")  # fmt: skip
    for kind, row in r.built_kinds.items():  # the other kinds of map (fingerprints/kinds.py)
        o, tk = getattr(row["ours/default"], k), getattr(row["tap_oracle/default"], k)
        t.add(f"{what}: kind {kind}, default matcher: ours {o:.2f} m ÷ points' {ours:.2f}; tap "
              f"oracle of that kind {tk:.2f} m", o / ours, "×", "{:,.3f}")  # fmt: skip


def kind_build_seconds(t: Table, repeat: int = 5) -> None:
    """Building the interpolated map of mall B1 (its 157 walks' scans at their tapped truth:
    the same number of points as ours, no pipeline run needed): median and spread."""
    import statistics
    import time

    from workstation.fingerprints.kinds import build
    from workstation.fingerprints.localize import Fingerprints
    from workstation.session import load_session

    files = sorted((SHARED_DATA / "microsoft-ilc2020-site1-b1" / "path_data_files").glob("*.gz"))
    if not files:
        t.add("interpolated map of B1: the floor is absent, left out", 0, "", "{:,.0f}")
        return
    merged = Fingerprints.merge([Fingerprints.from_session(load_session(p)) for p in files])
    secs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        built = build("interpolated", merged)
        secs.append(time.perf_counter() - t0)
    med = statistics.median(secs)
    t.add(f"interpolated map of B1 ({len(files)} walks, {len(merged):,} points → {len(built):,}), "
          f"median of {repeat} (spread {min(secs):.2f}–{max(secs):.2f} s)  "
          f"[≤ 20 s: {'ok' if med <= 20 else 'NOT MET'}]", med, "s", "{:,.2f}")  # fmt: skip


def uji(t: Table) -> None:
    from workstation.fingerprints.localize import errors, localize
    from workstation.fingerprints.matchers import DEFAULT, METHODS
    from workstation.fingerprints.uji import read_uji

    z = SHARED_DATA / "ujiindoorloc" / "UJIIndoorLoc.zip"
    if not z.is_file():
        t.add(f"UJIIndoorLoc: {z} absent, left out", 0, "", "{:,.0f}")
        return
    train, val = read_uji(z)
    e = errors(localize(train, val, tau=-90.0, align_device=False, matcher=METHODS[DEFAULT]), val)
    ok = e["mean_m"] <= 7.0 and e["floor_accuracy"] >= 0.89
    t.add(f"UJIIndoorLoc, default: mean where the floor is right (floor "
          f"{100 * e['floor_accuracy']:.1f} %)  [≤ 7.0 m, ≥ 89 %: {'ok' if ok else 'NOT MET'}]",
          e["mean_m"], "m", "{:,.2f}")  # fmt: skip
