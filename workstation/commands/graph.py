"""``workstation graph``: build landmark graphs from route files or walks, and check them."""

from __future__ import annotations

from pathlib import Path

from workstation.io.store import local_output


def _graph_from_tra(args) -> int:
    from workstation.graph.importers import graph_from_tra
    g = graph_from_tra(args.files)
    return _saved(g, args.output, f"floors {', '.join(str(int(f)) for f in g.floors)}")


def _saved(g, output, what: str) -> int:
    """The graph written, and what it holds said: landmarks (with rules), edges, ``what``."""
    g.save(output)
    n_rules = sum(1 for n in g.nodes if n.rules)
    print(
        f"wrote {output}: {len(g.nodes)} landmarks ({n_rules} with detection rules), "
        f"{len(g.undirected_pairs())} edges, {what}"
    )
    return 0


def _graph_from_waypoints(args) -> int:
    from workstation.io.atomic import atomic_write_text, check_outputs
    from workstation.progress import Progress
    from workstation.session import load_session
    from workstation.walks.graph_from_walks import graph_from_walks, report_markdown

    outs = [Path(args.output)] + ([] if args.per_tap else [Path(args.output).with_suffix(".report.md")])
    check_outputs(outs, backups=outs[:1])  # all of them before anything is written
    bar = Progress()  # 106 mall walks: half a minute, said (issue #50 item 9)
    sessions = []
    for k, p in enumerate(args.sessions, 1):
        sessions.append(load_session(p))
        bar(k, len(args.sessions), Path(p).name, phase="loading walks")
    if args.per_tap:
        return _per_tap(args, sessions)

    # a walk with fewer than two taps draws nothing: left out and named (when none has two,
    # the first goes on to be refused, by name)
    kept = [k for k, s in enumerate(sessions) if s.has_path] or [0]
    skipped = [str(p) for k, p in enumerate(args.sessions) if k not in kept]
    sessions = [sessions[k] for k in kept]
    g, reports = graph_from_walks(sessions, progress=bar)
    bar.close()
    g.save(args.output)
    md = Path(args.output).with_suffix(".report.md")
    walks = [str(args.sessions[k]) for k in kept]
    atomic_write_text(md, report_markdown(g, reports, walks, skipped))
    print(_graph_words(args.output, g, sessions))
    if skipped:
        left = len(skipped)
        print(f"left out {left} walk{'s' if left != 1 else ''} with fewer than two taps: "
              + ", ".join(skipped))  # fmt: skip
    print(f"wrote {md}: per landmark, the taps merged into it and why it has its rules")
    print(f"look at it on the plan and fix it: workstation edit WALK --graph {args.output}")
    return 0


def _per_tap(args, sessions) -> int:
    """``--per-tap``: one landmark per tap (graph.importers.graph_from_waypoints)."""
    from workstation.graph.importers import graph_from_waypoints

    return _saved(graph_from_waypoints(sessions, args.merge), args.output, "one landmark per tap")


def _graph_words(output, g, sessions) -> str:
    """What was drawn from the walks: landmarks, taps, walks, edges and rules."""
    taps = sum(len(s.ground_truth) for s in sessions if s.ground_truth is not None)
    by: dict[str, int] = {}
    for n in g.nodes:
        key = "+".join(sorted(n.rules)) or "no rule"
        by[key] = by.get(key, 0) + 1
    return (f"wrote {output}: {len(g.nodes)} landmarks from {taps} taps of {len(sessions)} "
            f"walk{'s' if len(sessions) != 1 else ''} (where walks turn, begin, end or meet), "
            f"{len(g.undirected_pairs())} edges; "
            "rules: " + ", ".join(f"{k} {v}" for k, v in sorted(by.items())))  # fmt: skip


def _graph_validate(args) -> int:
    from workstation.graph import LandmarkGraph
    g = LandmarkGraph.load(args.path)
    print(
        f"{args.path}: valid — {len(g.nodes)} landmarks, {len(g.undirected_pairs())} edges, floors {g.floors}"
    )
    return 0


def add_parser(sub) -> None:
    graph = sub.add_parser("graph", help="landmark graph tools")
    gsub = graph.add_subparsers(dest="graph_command", required=True)
    ft = gsub.add_parser("from-tra", help="build a landmark graph from IPIN .tra route files")
    ft.add_argument("files", nargs="+", type=Path)
    ft.add_argument("-o", "--output", type=local_output, required=True)
    ft.set_defaults(func=_graph_from_tra)
    fw = gsub.add_parser(
        "from-waypoints",
        help="build a landmark graph from the ground-truth points (tapped waypoints) of walks",
    )
    fw.add_argument("sessions", nargs="+", type=Path)
    fw.add_argument("-o", "--output", type=local_output, required=True)
    fw.add_argument(
        "--per-tap",
        action="store_true",
        help="one landmark per tapped point (the old way) instead of where walks turn or meet",
    )
    fw.add_argument(
        "--merge",
        type=float,
        default=1.0,
        help="with --per-tap: points closer than this (m) on one floor are one landmark",
    )
    fw.set_defaults(func=_graph_from_waypoints)
    gv = gsub.add_parser("validate", help="check a landmark graph YAML")
    gv.add_argument("path", type=Path)
    gv.set_defaults(func=_graph_validate)
