"""``workstation demo``: what ``make demo`` runs — the pipeline on the bundled office walk, its
results written, its recording opened in a viewer (or saved where there is no display)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from workstation.errors import WorkstationError
from workstation.io.store import local_output


def add_parser(sub) -> None:
    demo = sub.add_parser("demo", help="run the main job on the bundled samples")
    demo.add_argument("--out", type=local_output, default=Path("out"))
    demo.add_argument(
        "--save-only", action="store_true", help="save the recording even when a display exists"
    )
    demo.set_defaults(func=_demo)


def _demo(args) -> int:
    """The main job on the bundled paper-like sample: run the pipeline on the `normal` walk,
    write its results, and open the recording in the Rerun viewer (or save it when no display)."""
    from workstation.commands.walk import info, run, view
    root = Path(__file__).resolve().parents[2] / "sample_sessions" / "office2f"
    walk = root / "normal"
    if not (walk / "session.yaml").is_file():
        raise WorkstationError(f"bundled sample missing: {walk}")
    out = Path(args.out)
    from workstation.session import load_session

    model = load_session(walk).metadata.extra.get("model", "ideal")
    print(
        f"== {walk.name}: the bundled two-floor office walk, simulated with the {model} model"
        + (
            " (walks and phones as real ones: workstation/sim/realism.py)"
            if model == "realistic"
            else ""
        )
    )
    info(argparse.Namespace(path=walk, json=False))
    ns = argparse.Namespace(
        session=walk,
        graph=walk / "graph.yaml",
        params=None,
        start=None,
        out=out / "normal",
        plan=None,
        layout="overview",
        map=None,  # run's --map: no building map in the demo
    )
    run(ns)
    display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    if display and not args.save_only:
        ns.connect, ns.save = None, None
    else:
        ns.connect, ns.save = None, out / "normal.rrd"
    view(ns)
    return 0
