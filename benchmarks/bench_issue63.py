"""Issue #63's lines: on each floor the default matcher on our merged map against the paper's
1-NN and the tap oracle (same matcher, and 1-NN), from the same splits as issue #62's table
(bench_issues.floors), and UJIIndoorLoc with the default."""

from __future__ import annotations

from _common import SHARED_DATA, Table


def _bar(t: Table, what: str, value: float, ok: bool, bar: str) -> None:
    t.add(f"{what}  [{bar}: {'ok' if ok else 'NOT MET'}]", value, "×", "{:,.3f}")


def floor_rows(t: Table, what: str, r, covered: bool) -> None:
    """One floor's lines: the default ÷ the paper's 1-NN on our map, ÷ the tap oracle under
    1-NN and under the same matcher (``r.matchers``, evaluate/map_kinds.score_matchers)."""
    from workstation.fingerprints.matchers import DEFAULT, PAPER

    k = "covered_mean_with_floor_penalty_m" if covered else "mean_with_floor_penalty_m"
    d, p = r.matchers[DEFAULT], r.matchers[PAPER]
    ours, ours1, tap, tap1 = d["ours"][k], p["ours"][k], d["tap_oracle"][k], p["tap_oracle"][k]
    _bar(t, f"{what}: default on our map ÷ 1-NN on it ({ours:.2f} / {ours1:.2f} m)", ours / ours1,
         ours <= 0.85 * ours1, "≤ 0.85")  # fmt: skip
    _bar(t, f"{what}: default ÷ tap oracle with 1-NN ({tap1:.2f} m)", ours / tap1,
         ours <= 0.90 * tap1, "≤ 0.90")  # fmt: skip
    _bar(t, f"{what}: ours ÷ tap oracle, same matcher ({tap:.2f} m)", ours / tap,
         ours <= 1.05 * tap, "≤ 1.05")  # fmt: skip


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
