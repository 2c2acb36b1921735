"""The kinds-of-map and matchers tables of results.md (issue #63): every matcher and every
kind of map on the same queries, ours beside the tap oracle."""

from __future__ import annotations

from workstation.evaluate.walks import LooResult
from workstation.fingerprints.matchers import DEFAULT, METHODS, PAPER


def matchers_markdown(res: LooResult) -> list[str]:
    """Every matcher of the table on the same queries (issue #63): our map, every row and the
    tap oracle under it, ours against the tap oracle under the same matcher and under the
    paper's 1-NN (what a surveyor tapping and matching 1-NN would get)."""
    if not res.matchers:
        return []
    key = "covered_mean_with_floor_penalty_m" if res.queries_every <= 1 else "mean_with_floor_penalty_m"
    tap1 = getattr(res.matchers[PAPER]["tap_oracle"], key)
    L = ["", f"Every matcher on the same queries ({'covered queries, ' if res.queries_every <= 1 else ''}"
         "mean with the floor penalty, m); the default is "
         f"{DEFAULT}, the paper's {PAPER}:", "",
         "| matcher | ours | every row | tap oracle | ours / tap, same matcher | ours / tap with 1-NN |",
         "|---|---|---|---|---|---|"]  # fmt: skip
    for name, row in res.matchers.items():
        o, e, t = (getattr(row[k], key) for k in ("ours", "ours_unfiltered", "tap_oracle"))
        mark = " (default)" if name == DEFAULT else ""
        L.append(f"| {name}{mark}: {METHODS[name].words()} | {o:.2f} | {e:.2f} | {t:.2f} | "
                 f"{o / t:.3f} | {o / tap1:.3f} |")  # fmt: skip
    return L


def built_kinds_markdown(res: LooResult) -> list[str]:
    """Every kind of map (fingerprints/kinds.py) on the same queries (issue #63): built from
    our map and from the tap oracle's, under the selected matcher and the paper's 1-NN, beside
    the points themselves."""
    if not res.matchers:
        return []
    if not res.built_kinds:
        return ["", "Other kinds of map (fingerprints/kinds.py): scored when the walks are split "
                "(--queries-every N), or when at most 12 walks leave one out (a map per walk)."]
    key = "covered_mean_with_floor_penalty_m" if res.queries_every <= 1 else "mean_with_floor_penalty_m"
    rows = {"points": {f"{s}/{lab}": v for s in ("ours", "tap_oracle")
                       for lab, v in (("default", getattr(res.loo[s], key)),
                                      ("1nn", getattr(res.matchers[PAPER][s], key)))}}  # fmt: skip
    rows |= {k: {c: getattr(v, key) for c, v in r.items()} for k, r in res.built_kinds.items()}
    L = ["", "Every kind of map on the same queries (mean with the floor penalty, m; "
         f"fingerprints/kinds.py), under the selected matcher and the paper's {PAPER}:", "",
         "| kind | ours | tap oracle | ours / tap | ours, 1-NN | tap oracle, 1-NN |",
         "|---|---|---|---|---|---|"]  # fmt: skip

    def f(v):
        return "–" if v is None else f"{v:.2f}"

    for kind, r in rows.items():
        o, t = r.get("ours/default"), r.get("tap_oracle/default")
        ratio = f"{o / t:.3f}" if o and t else "–"
        L.append(f"| {kind} | {f(o)} | {f(t)} | {ratio} | {f(r.get('ours/1nn'))} | "
                 f"{f(r.get('tap_oracle/1nn'))} |")  # fmt: skip
    return L
