"""``workstation realism WALK...``: how walks look to the pipeline — the quantities of
workstation/sim/realism.py for each walk, beside the real museum walks' range."""

from __future__ import annotations

import math
from pathlib import Path


def add_parser(sub) -> None:
    r = sub.add_parser(
        "realism",
        help="measure gait, stops, turns, compass, pressure and APs of walks against real walks",
        epilog="example: workstation realism sample_sessions/office2f/normal",
    )
    r.add_argument("walks", nargs="+", type=Path)
    r.set_defaults(func=_run)


def _run(args) -> int:
    from workstation.session import load_session
    from workstation.sim.realism import REAL_RANGES, measure

    got = {w.name: measure(load_session(w)) for w in args.walks}
    names = list(got)
    print(f"{'quantity':<30}{'real walks':>20}  " + "  ".join(f"{n[:14]:>14}" for n in names))
    for k, (lo, hi) in REAL_RANGES.items():
        cells = []
        for n in names:
            v = got[n].get(k, math.nan)
            flag = " " if (lo <= v <= hi) else "*"
            cells.append(f"{v:>13.4g}{flag}")
        print(f"{k:<30}{f'{lo:.3g} – {hi:.3g}':>20}  " + "  ".join(cells))
    print("* outside the range of the 10 IPIN museum walks")
    return 0
