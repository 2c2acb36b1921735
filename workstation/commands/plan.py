"""``workstation plan``: the walk that covers the building (or re-walks where the map is thin),
cut into recordings, with what to do at each landmark — ``plan.md``, ``plan.json``,
``plan.geojson`` and a PNG per floor."""

from __future__ import annotations

import json
from pathlib import Path

from workstation.errors import InputError, WorkstationError
from workstation.io.store import local_output, path_or_url


def add_parser(sub) -> None:
    p = sub.add_parser(
        "plan",
        help="plan the survey walk (every edge) or the re-walk of a map's thin edges",
    )
    p.add_argument("--graph", type=Path, required=True)
    p.add_argument("--building", type=Path, help="building file: the route drawn on its plans")
    thin = p.add_mutually_exclusive_group()
    thin.add_argument(
        "--map", type=path_or_url, action="append",
        help="radio map (repeat): plan only the re-walk of the edges it covers thinly",
    )  # fmt: skip
    thin.add_argument(
        "--quality", type=Path, metavar="DIR",
        help="a `workstation quality` folder: re-walk its edges_to_rewalk",
    )  # fmt: skip
    p.add_argument("--start", help="start landmark: an open route from it (default: a closed one)")
    p.add_argument(
        "--max-minutes", type=float, help="cut the route into walks of at most this long"
    )
    p.add_argument(
        "--walks", type=Path, nargs="+", metavar="WALK",
        help="the building's recorded walks: measure step length, cadence, scan interval and "
        "standing time from them (default: the pipeline's defaults)",
    )  # fmt: skip
    p.add_argument("--params", type=Path, help="parameters YAML (for the pace's defaults)")
    p.add_argument(
        "--gap-m", type=float, default=None,
        help="with --map: an edge is thin where over half of it is farther than this from "
        "every reference point (default 5)",
    )  # fmt: skip
    p.add_argument("--include-quarantined", action="store_true", help="with --map: use them too")
    p.add_argument("--force", action="store_true", help="plan even when map and graph disagree")
    p.add_argument("--out", type=local_output, required=True)
    p.set_defaults(func=_run)


def _quality_edges(folder: Path, graph) -> list[tuple[str, str]]:
    path = folder / "quality.json" if folder.is_dir() else folder
    try:
        report = json.loads(path.read_text(encoding="utf-8"))
        names = [e for f in report["floors"] for e in f["edges_to_rewalk"]]
    except FileNotFoundError:
        raise InputError(path, "not found: give the folder `workstation quality` wrote") from None
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise InputError(path, f"not a quality report ({type(e).__name__}: {e})") from None
    by_name = {f"{a}-{b}": (a, b) for u, v in graph.undirected_pairs() for a, b in [sorted((u, v))]}
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise InputError(path, f"edges not in the graph: {', '.join(map(str, unknown[:5]))}")
    return [by_name[n] for n in names]


def _pace(args, graph, params):
    from workstation.progress import Progress
    from workstation.survey_plan.pace import default_pace, measure_pace
    base = default_pace(params)
    if not args.walks:
        return base
    from workstation.pipeline import Pipeline
    from workstation.session import load_session

    results, progress = [], Progress()
    for i, w in enumerate(args.walks, 1):
        s = load_session(w)
        s = s.in_frame(graph.frame)
        results.append(Pipeline(s, graph, params).run())
        progress(i, len(args.walks), f"pace from {Path(w).name}", phase="measuring the pace")
    progress.close()
    return measure_pace(results, base)


def _required(args, graph) -> list | None:
    """The edges the plan must walk: where the map (``--map``) or a quality report
    (``--quality``) is thin; None: every edge."""
    from workstation.building.consistency import plan_mismatches, refuse
    from workstation.commands.radiomap import read_maps
    from workstation.fingerprints.localize import Fingerprints
    from workstation.fingerprints.quality import GAP_M, thin_edges

    if args.map:
        fp = Fingerprints.merge(read_maps(args.map, args.include_quarantined), align_devices=False)
        what = ", ".join(str(p) for p in (*args.map, args.graph))
        refuse(what, plan_mismatches(fp, graph), args.force)
        return list(thin_edges(fp, graph, args.gap_m or GAP_M))
    if args.quality:
        return _quality_edges(args.quality, graph)
    return None


def _plan_words(t: dict, required: list | None, any_required: bool, graph_path) -> str:
    """The plan's first line: its walks, time, distance and scans — or why there is nothing."""
    if required is not None and not required:
        return "the map covers every edge: nothing to re-walk"
    if not any_required:
        return f"nothing to walk: {graph_path} has no edge between landmarks on one floor"
    bound = t["lower_bound_s"]
    return (f"{t['walks']} walk(s), {t['duration_s'] / 60:.1f} min, {t['distance_m']:.0f} m, "
            f"about {t['scans']} scans; {t['required_edges']} "
            f"edge{'' if t['required_edges'] == 1 else 's'} to walk"
            + (f"; walking {t['route_walking_s']:.0f} s, lower bound {bound:.0f} s" if bound
               else ""))  # fmt: skip


def _run(args) -> int:
    from workstation.commands.plan_figure import draw_plan_floors
    from workstation.graph import LandmarkGraph
    from workstation.params import Params
    from workstation.survey_plan.output import totals, write_plan
    from workstation.survey_plan.plan import plan_survey
    graph = LandmarkGraph.load(args.graph)
    params = Params.load(args.params) if args.params else Params()
    if args.max_minutes is not None and not 0.5 <= args.max_minutes <= 600:
        raise WorkstationError(f"--max-minutes {args.max_minutes:g}: give 0.5–600 minutes")
    if args.start is not None and args.start not in graph.ids:
        raise WorkstationError(f"--start {args.start}: no such landmark in {args.graph}")
    required = _required(args, graph)
    pace = _pace(args, graph, params)
    try:
        plan = plan_survey(graph, pace, required, args.start, args.max_minutes)
    except ValueError as e:
        raise WorkstationError(f"{args.graph}: {e}") from None
    paths = write_plan(plan, graph, args.out, args.max_minutes)
    if args.building:
        paths += draw_plan_floors(plan, graph, args.building, args.out)
    print(_plan_words(totals(plan), required, bool(plan.required), args.graph))
    for w in plan.walks:
        over = args.max_minutes and w.duration_s > args.max_minutes * 60
        print(
            f"  walk {w.index}: {w.start} → {w.end}, {w.duration_s / 60:.1f} min, "
            f"{w.distance_m:.0f} m"
            + ("  (over the limit: no rule landmark to end at sooner)" if over else "")
        )
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0
