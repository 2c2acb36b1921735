"""The thin `workstation` command: the parser. Each subcommand's body is in :mod:`.commands`."""

from __future__ import annotations

import argparse
import difflib
import sys
from pathlib import Path

from workstation.commands import (
    building,
    campaign,
    demo,
    edit,
    examples,
    graph,
    layouts,
    plan,
    quality,
    radiomap,
    realism,
    simulate,
    walk,
)
from workstation.commands.evaluate import add_parser as add_evaluate
from workstation.errors import WorkstationError
from workstation.io.store import LOCAL_ONLY, local_output, output_path, path_or_url


def _port(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a port number") from None
    if not 0 <= v <= 65535:
        raise argparse.ArgumentTypeError(f"{v} is not a port (0-65535)")
    return v


def _reach(text: str) -> tuple[float, float, float | None, float]:
    """``X,Y,FLOOR,R`` (FLOOR ``any``: every floor) for ``edit --start-within``."""
    parts = text.split(",")
    try:
        if len(parts) != 4:
            raise ValueError
        x, y, r = float(parts[0]), float(parts[1]), float(parts[3])
        floor = None if parts[2].strip() == "any" else float(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: give X,Y,FLOOR,R in metres (FLOOR a number or 'any'), e.g. 75.4,94.8,0,16"
        ) from None
    if not r > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: the radius R must be positive")
    return x, y, floor, r


def _walk_args(p: argparse.ArgumentParser, plan: bool = True) -> None:
    """The arguments every command that runs the pipeline on a walk takes."""
    p.add_argument("session", type=path_or_url)
    p.add_argument("--graph", type=path_or_url, required=True)
    p.add_argument("--params", type=path_or_url)
    p.add_argument(
        "--start",
        help="start landmark id, 'first-fix' (the landmark at the first ground-truth fix) or 'infer' (the default)",
    )
    p.add_argument(
        "--end",
        help="landmark id the walk ended on (the surveyor stopped recording there), or 'last-fix' "
        "(the landmark at the last ground-truth fix): its last stretch is closed on it, and it "
        "checks a walk that matched nothing when the sensors agree (pdr.end_node)",
    )
    p.add_argument(
        "--start-within", type=_reach, metavar="X,Y,FLOOR,R",
        help="infer the start only among the landmarks within R m of X,Y on FLOOR ('any': on "
        "every floor): where the walk recorded just before this one ended (campaign.md gives it)",
    )  # fmt: skip
    if plan:
        p.add_argument(
            "--plan", type=Path, help="wall plan YAML (default: floorplan.yaml beside the graph)"
        )
        p.add_argument(
            "--building",
            type=path_or_url,
            help="building file with floor-plan images (default: building.yaml beside the graph)",
        )
    p.add_argument("--force", action="store_true", help="run even when walk and graph do not match")


def _map_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--map", type=path_or_url, nargs="+", metavar="RADIOMAP",
        help="the building's radio map(s) of its other walks (merge's, radiomap.csv): where it "
        "puts this walk's scans weighs in choosing among the chains of matches the sensors "
        "cannot tell apart (pdr.map_weight; never the start), and when the inferred start is "
        "ambiguous, its candidate starts are ranked by how well each agrees with it (a hint)",
    )  # fmt: skip


_ARGV: list[str] = []  # the command line being parsed (for _Parser's suggestions)


class _Formatter(argparse.HelpFormatter):
    """argparse's help, but an epilog that gives an example command is not wrapped: a wrapped
    path does not copy and paste (issue #64 item 7)."""

    def _fill_text(self, text, width, indent):
        if text.lstrip().startswith("example"):
            return "\n".join(indent + line for line in text.splitlines())
        return super()._fill_text(text, width, indent)


class _Parser(argparse.ArgumentParser):
    """argparse that names the option a misspelled one was probably meant to be: ``--grpah``
    gave only "the following arguments are required: --graph"."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):  # type: ignore[override,unused-ignore]
        if LOCAL_ONLY in message:  # a store's URL where only a local output is written: one line
            self.exit(2, f"{self.prog}: error: {message}\n")

        known, commands = _known_of(self)
        hints = []
        for tok in _ARGV:
            opt = tok.split("=", 1)[0]
            if opt.startswith("--") and opt not in known:
                close = difflib.get_close_matches(opt, known, n=1, cutoff=0.6)
                if close:
                    hints.append(f"{opt}: did you mean {close[0]}?")
        if "invalid choice" in message and commands:
            typed = next((t for t in _ARGV if not t.startswith("-")), "")
            close = difflib.get_close_matches(typed, commands, n=1, cutoff=0.5)
            if close and typed not in commands:
                hints.append(f"{typed}: did you mean {close[0]}?")
        super().error("; ".join([message, *hints]))


def _known_of(parser: argparse.ArgumentParser) -> tuple[list[str], list[str]]:
    """The long options one may type here — the parser's, and the typed subcommand's (an
    unknown one is said by the top parser) — and the subcommands' names."""
    known = [s for a in parser._actions for s in a.option_strings if s.startswith("--")]
    commands: list[str] = []
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            commands += list(a.choices)
            sub = next((a.choices[t] for t in _ARGV if t in a.choices), None)
            if sub is not None:
                known += [s for b in sub._actions for s in b.option_strings if s[:2] == "--"]
    return known, commands


S = "sample_sessions/office2f/normal"  # the walk the examples use


def _info_parser(sub) -> None:
    """`info`: a walk summarised."""
    info = sub.add_parser(
        "info",
        help="summarise a walk (logfile, path file or session folder)",
        description="Streams, rates, WiFi scans, ground truth and what the reader skipped.",
        epilog=f"example: workstation info {S}",
    )
    info.add_argument("path", type=path_or_url)
    info.add_argument("--json", action="store_true", help="print the summary as JSON")
    info.set_defaults(func=walk.info)


def _run_parser(sub) -> None:
    """`run`: the pipeline on one walk, its results written."""
    run = sub.add_parser(
        "run",
        help="run the pipeline on a walk and write its results",
        description="Steps, heading, landmark detections, landmark-graph PDR, belief and the "
        "radio map, for one walk. SESSION: a GetSensorData/IPIN logfile, a Microsoft ILC path "
        "file or a session folder. Writes trajectory.csv, landmarks.csv, segments.csv, "
        "radiomap.csv and summary.json to --out.",
        epilog=f"example: workstation run {S} --graph {S}/graph.yaml --out out/normal",
    )
    _walk_args(run, plan=False)
    run.add_argument("--out", type=output_path, required=True,
                     help="a folder here, or a store's URL (s3://…)")  # fmt: skip
    _map_arg(run)
    run.set_defaults(func=walk.run)


def _view_parser(sub) -> None:
    """`view`: as run, every stage streamed to Rerun."""
    view = sub.add_parser(
        "view",
        help="run the pipeline and stream every stage to the Rerun viewer",
        description="As run, and every stage logged to Rerun: a viewer opens (or --save FILE.rrd, "
        "--connect URL). The plan image of building.yaml beside the graph is drawn under the map.",
        epilog=f"example: workstation view {S} --graph {S}/graph.yaml --save out/normal.rrd",
    )
    _walk_args(view)
    view.add_argument("--layout", default="overview", help="overview | landmarks | radiomap")
    _map_arg(view)  # also: every scan localized on it, drawn beside the walk's track
    view.add_argument(
        "--route", type=Path, metavar="PLAN.json",
        help="draw a survey plan (workstation plan) under the graph",
    )  # fmt: skip
    dest = view.add_mutually_exclusive_group()
    dest.add_argument(
        "--connect",
        metavar="URL",
        help="stream to a running viewer, e.g. rerun+http://127.0.0.1:9876/proxy",
    )
    dest.add_argument(
        "--save", type=local_output, metavar="FILE.rrd", help="write a recording instead of streaming"
    )
    view.set_defaults(func=walk.view)


def _split_parser(sub) -> None:
    """`split`: a walk cut in two."""
    sp = sub.add_parser(
        "split",
        help="cut a walk in two (two recordings joined, or a pause of its sensors)",
        description="Writes WALK as two session folders OUT/NAME-1 and OUT/NAME-2, cut at "
        "--at SECONDS from its first accelerometer/gyroscope sample, by default in the middle "
        "of its longest pause of those sensors (the sensor_hole quarantine names it), else "
        "where a second recording begins (two_clocks), else where its compass turned alone "
        "(facing_jump).",
        epilog="example: workstation split joined.txt --out parts",
    )
    sp.add_argument("walk", type=Path, help="a logfile, path file or session folder")
    sp.add_argument("--out", type=local_output, required=True, help="where the two parts go")
    sp.add_argument("--at", type=float, metavar="SECONDS",
                    help="where to cut, from the first accelerometer/gyroscope sample")
    sp.set_defaults(func=walk.split)


def _layouts_parser(sub) -> None:
    """`layouts`: the Rerun blueprints written."""
    lay = sub.add_parser("layouts", help="write the Rerun blueprints (.rbl) generated from code")
    lay.add_argument("--out", type=local_output, default=Path("layouts"))
    lay.set_defaults(func=layouts.run)


def _edit_parser(sub) -> None:
    """`edit`: the survey panel in the browser."""
    ed = sub.add_parser(
        "edit",
        help="browser panel: edit the landmark graph, tune thresholds, re-run, export",
        description="Serves the survey panel on http://127.0.0.1:PORT: draw or fix the graph on "
        "the plan, tune parameters, see the result at once, save and export. A --graph that does "
        "not exist yet starts a new graph. Unsaved edits are kept in GRAPH.recovery.",
        epilog=f"example: workstation edit {S} --graph {S}/graph.yaml --no-viewer",
    )
    _walk_args(ed)
    ed.add_argument(
        "--host", default="127.0.0.1", help="bind address (default 127.0.0.1: this machine only)"
    )
    ed.add_argument("--port", type=_port, default=8080)
    _map_arg(ed)
    ed.add_argument(
        "--out", type=local_output, default=Path("out"), help="where exports and saved parameters go"
    )
    ed.add_argument(
        "--campaign-walk", metavar="NAME",
        help="the walk's name in a campaign (campaign.md gives it): 'Start here' and 'End here' "
        "also write NAME: LANDMARK to --starts-file / --ends-file, where the campaign reads it",
    )  # fmt: skip
    ed.add_argument("--starts-file", type=path_or_url, metavar="STARTS.yaml",
                    help="with --campaign-walk: the building's starts.yaml")  # fmt: skip
    ed.add_argument("--ends-file", type=path_or_url, metavar="ENDS.yaml",
                    help="with --campaign-walk: the building's ends.yaml")  # fmt: skip
    rr_dest = ed.add_mutually_exclusive_group()
    rr_dest.add_argument(
        "--connect", metavar="URL", help="stream re-runs to a running Rerun viewer"
    )
    rr_dest.add_argument("--save", type=local_output, metavar="FILE.rrd", help="record re-runs to a file")
    rr_dest.add_argument("--no-viewer", action="store_true", help="do not stream to Rerun")
    ed.set_defaults(func=edit.run)


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="workstation",
        description="Survey workstation: one smartphone walk -> a trustworthy WiFi radio map.",
    )

    sub = p.add_subparsers(dest="command", required=True)
    for add in (_info_parser, _run_parser, _view_parser, _split_parser, _layouts_parser,
                _edit_parser, radiomap.add_parsers, add_evaluate, simulate.add_parser,
                graph.add_parser, building.add_parser, campaign.add_parser, quality.add_parser,
                plan.add_parser, realism.add_parser, demo.add_parser):  # fmt: skip
        add(sub)

    examples.apply(p)
    return p


def main(argv: list[str] | None = None) -> int:
    _ARGV[:] = list(sys.argv[1:] if argv is None else argv)
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except WorkstationError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(
            "interrupted — files already written are whole (each is written atomically); "
            "run the same command again",
            file=sys.stderr,
        )
        return 130
    except BrokenPipeError:  # output piped into head & co.
        sys.stderr.close()
        return 0
    except OSError as e:  # a folder not writable, an existing file where a folder goes, a full disk
        where = e.filename or "a file"
        print(f"error: {where}: {e.strerror or e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
