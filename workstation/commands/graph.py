"""``workstation graph``: build landmark graphs from route files or walks, and check them."""

from __future__ import annotations

from pathlib import Path


def _graph_from_tra(args) -> int:
    from ..graph import graph_from_tra

    g = graph_from_tra(args.files)
    g.save(args.output)
    n_rules = sum(1 for n in g.nodes if n.rules)
    print(
        f"wrote {args.output}: {len(g.nodes)} landmarks ({n_rules} with detection rules), "
        f"{len(g.undirected_pairs())} edges, floors {', '.join(str(int(f)) for f in g.floors)}"
    )
    return 0


def _graph_from_waypoints(args) -> int:
    from ..graph import graph_from_waypoints
    from ..session import load_session

    g = graph_from_waypoints([load_session(p) for p in args.sessions], args.merge)
    g.save(args.output)
    n_rules = sum(1 for n in g.nodes if n.rules)
    print(
        f"wrote {args.output}: {len(g.nodes)} landmarks ({n_rules} with detection rules), {len(g.undirected_pairs())} edges"
    )
    return 0


def _graph_validate(args) -> int:
    from ..graph import LandmarkGraph

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
    ft.add_argument("-o", "--output", type=Path, required=True)
    ft.set_defaults(func=_graph_from_tra)
    fw = gsub.add_parser(
        "from-waypoints",
        help="build a landmark graph from the ground-truth points (tapped waypoints) of walks",
    )
    fw.add_argument("sessions", nargs="+", type=Path)
    fw.add_argument("-o", "--output", type=Path, required=True)
    fw.add_argument(
        "--merge",
        type=float,
        default=1.0,
        help="points closer than this (m) on one floor are one landmark",
    )
    fw.set_defaults(func=_graph_from_waypoints)
    gv = gsub.add_parser("validate", help="check a landmark graph YAML")
    gv.add_argument("path", type=Path)
    gv.set_defaults(func=_graph_validate)
