"""``workstation evaluate``: argument parsing and printing (the experiments live beside it)."""

from __future__ import annotations

import argparse
from pathlib import Path

from workstation.io.store import local_output


def add_parser(sub) -> None:
    ev = sub.add_parser(
        "evaluate",
        help="regenerate the paper's experiments, or leave-one-walk-out on your own walks",
        description="Without --walks: the paper's experiments on the simulated office, and the "
        "IPIN museum walks when ../shared/data is there. With --walks: each walk localized on "
        "the radio map of the others (walks need ground-truth fixes). Writes results.md, "
        "results.json (and figures) to --out.",
    )
    ev.add_argument("--out", type=local_output, required=True)
    ev.add_argument(
        "--shared",
        type=Path,
        help="../shared/data with the real walks (default: found beside the checkout)",
    )
    ev.add_argument("--seed", type=int, default=1)
    ev.add_argument(
        "--model", default="realistic", choices=["realistic", "ideal"],
        help="simulator model for the simulated experiments (default realistic)",
    )  # fmt: skip
    ev.add_argument(
        "--seeds", type=int, default=10, help="seeds of the robustness and density tables"
    )
    ev.add_argument("--walks", type=Path, nargs="+", metavar="WALK", help="walks with ground truth")
    ev.add_argument("--graph", type=Path, help="the landmark graph of the walks' building")
    ev.add_argument("--params", type=Path, help="parameter YAML (default: the defaults)")
    ev.add_argument(
        "--queries-every",
        type=int,
        default=0,
        metavar="N",
        help="with --walks: a split instead of leave-one-out — the walks sorted by name, every "
        "N-th one is a query walk, the others make the map",
    )
    ev.add_argument(
        "--start",
        default="first-fix",
        help="start landmark of every walk: 'first-fix' (default), 'infer' or a landmark id",
    )
    ev.add_argument(
        "--end",
        help="with --walks: every walk's end as a surveyor gives it ('last-fix': the landmark "
        "at its last ground-truth fix; pdr.end_node); not with --start infer",
    )
    ev.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from workstation.evaluate.command import run

    return run(args)
