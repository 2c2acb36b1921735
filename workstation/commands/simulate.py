"""``workstation simulate``: a simulated walk or manual survey as a session folder."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from workstation.errors import InputError, WorkstationError
from workstation.io.store import local_output


def _simulate(args) -> int:
    import numpy as np

    from workstation.sim import simulate
    from workstation.sim.graph_errors import perturb_graph

    interval = None
    if args.scan_interval:
        try:
            lo, _, hi = args.scan_interval.partition("-")
            interval = (float(lo), float(hi or lo))
        except ValueError:
            raise WorkstationError(
                f"--scan-interval {args.scan_interval!r}: give seconds as LOW-HIGH, e.g. 0.5-1"
            ) from None
    route = _plan_route(args.plan, args.plan_walk) if args.plan else None
    sim = simulate(
        args.building, args.walk, args.seed, args.model, interval, args.door_stops, route
    )
    if args.displace or args.drop_rules or args.drop_edges:
        g = perturb_graph(
            sim.graph, np.random.default_rng(args.seed + 10_000), args.displace,
            args.drop_rules, args.drop_edges,
        )  # fmt: skip
        sim = dataclasses.replace(sim, graph=g)
    out = sim.write(args.out)
    info = sim.session.info()
    extra = sim.session.metadata.extra
    what = (
        f"{info.duration_s:.0f} s walk, {info.scans} WiFi scans"
        if extra["kind"] == "walk"
        else f"manual survey, {extra['reference_points']} reference points, "
        f"{info.scans} scans"
    )
    print(f"wrote {out}: {what}; graph.yaml ({len(sim.graph.nodes)} landmarks), floorplan.yaml")
    print(
        f"  model: {args.model}"
        + (" (see workstation/sim/realism.py)" if args.model == "realistic" else "")
    )
    return 0


def _plan_route(path: Path, n: int) -> tuple[str, ...]:
    """Walk ``n`` (1-based) of a ``plan.json`` that ``workstation plan`` wrote, as landmark ids."""
    from workstation.survey_plan.output import read_plan_walks
    walks = read_plan_walks(path)
    if n not in walks:
        raise InputError(path, f"has no walk {n} (it has {len(walks)})")
    return tuple(walks[n])


def add_parser(sub) -> None:
    sim = sub.add_parser("simulate", help="simulate a walk (or the manual survey) in a building")
    sim.add_argument("--building", default="office2f")
    sim.add_argument(
        "--walk", default="normal", help="normal | varied | heldout | survey5 | survey10"
    )
    sim.add_argument("--seed", type=int, default=1)
    sim.add_argument(
        "--plan", type=Path, metavar="PLAN.json",
        help="walk a survey plan's route (workstation plan) instead; --walk gives the style",
    )  # fmt: skip
    sim.add_argument("--plan-walk", type=int, default=1, metavar="N", help="which walk of --plan")
    sim.add_argument("--out", type=local_output, required=True)
    sim.add_argument(
        "--model",
        default="realistic",
        choices=["realistic", "ideal"],
        help="realistic: walks and phones as real ones (default); ideal: the clean model",
    )
    sim.add_argument(
        "--scan-interval", metavar="LOW-HIGH", help="seconds between WiFi scans (default 2-4)"
    )
    sim.add_argument(
        "--no-door-stops", dest="door_stops", action="store_false",
        help="the walker does not stop at doors (their acc landmarks are not detected)",
    )  # fmt: skip
    sim.add_argument(
        "--displace",
        type=float,
        default=0.0,
        metavar="M",
        help="graph errors: displace every landmark by N(0, M) metres",
    )
    sim.add_argument(
        "--drop-rules",
        type=float,
        default=0.0,
        metavar="SHARE",
        help="graph errors: this share of landmarks lose their detection rule",
    )
    sim.add_argument(
        "--drop-edges", type=int, default=0, metavar="N", help="graph errors: leave out N edges"
    )
    sim.set_defaults(func=_simulate)
