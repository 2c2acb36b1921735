"""``workstation edit``: the survey panel over one walk, with Rerun as an optional observer;
unsaved work is named on Ctrl+C (recovery copies beside the graph)."""

from __future__ import annotations

import os
import time

from workstation.errors import WorkstationError


def run(args) -> int:
    """The panel over the walk: check the flags, load, the optional Rerun observer, the editor
    (the pipeline runs), the panel, serve until Ctrl+C, name what is unsaved."""
    from workstation.commands._inputs import building_map, load_inputs, plan_for, start_within

    _check_flags(args)
    print(f"loading {args.session} and {args.graph} …", flush=True)
    session, graph, params = load_inputs(args, new_graph_ok=True)
    ref = building_map(args, graph) if args.map else None  # a bad map: refused before the panel
    plan = plan_for(args)
    _say_recovery(args)
    observers = _rerun_observers(args, session, graph, plan)
    start_within(args, graph)  # says so when the reach holds no landmark
    print("running the pipeline (start inference, tracking, belief, radio map) …", flush=True)
    editor = _editor(args, session, graph, params, observers, ref)
    panel = _panel(args, editor, plan)
    print(f"survey panel: http://{args.host}:{panel.port}  (Ctrl-C to stop)", flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        panel.stop()
    _say_unsaved(editor)
    return 0


def _check_flags(args) -> None:
    from workstation.commands._inputs import check_host

    check_host(args.host)
    if (args.starts_file or args.ends_file) and not args.campaign_walk:
        raise WorkstationError("--starts-file and --ends-file need --campaign-walk NAME")
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(
            f"warning: --host {args.host}: the panel is reachable from other machines on the "
            "network; anyone who can reach it can edit and save the graph",
            flush=True,
        )


def _say_recovery(args) -> None:
    """A note when unsaved edits of an earlier session wait beside the graph."""
    from workstation.editor.recovery import recovery_paths
    from workstation.io.store import place

    rec_g = recovery_paths(place(args.graph), None, args.out)[0]
    if rec_g.is_file():
        print(
            f"note: {rec_g} holds unsaved edits from an earlier session; open it with "
            f"--graph {rec_g} to continue them",
            flush=True,
        )


def _rerun_observers(args, session, graph, plan) -> list:
    """The Rerun logger, when there is a display (or --save / --connect) and not --no-viewer."""
    from workstation.commands._inputs import building_for

    headless = not (args.save or args.connect or os.environ.get("DISPLAY")
                    or os.environ.get("WAYLAND_DISPLAY"))  # fmt: skip
    if headless and not args.no_viewer:  # the panel is a web page: it needs no display here
        print("note: no display for the Rerun viewer: the panel runs without it (--save FILE.rrd "
              "or --connect URL records the runs)", flush=True)  # fmt: skip
    if args.no_viewer or headless:
        return []
    from workstation.viz import layouts
    from workstation.viz.rerun_log import RerunLogger, new_recording, spawn_viewer

    rec = new_recording()
    baro = session.pressure is not None and len(session.pressure) > 0
    bp = layouts.default_blueprint("overview", graph, plan, baro, session)
    if args.save:
        rec.save(str(args.save), default_blueprint=bp)
    else:
        url = args.connect or spawn_viewer()[1]
        rec.connect_grpc(url, default_blueprint=bp)
    return [RerunLogger(rec, session, graph, plan, building_for(args))]


def _editor(args, session, graph, params, observers, ref):
    from workstation.editor import SurveyEditor
    from workstation.io.store import place
    from workstation.io.walk_fixes import WalkFixes

    editor = SurveyEditor(
        session,
        graph,
        params,
        graph_path=args.graph,
        params_path=args.params,
        out_dir=args.out,
        observers=observers,
        building_map=ref,
        start_within=args.start_within,
    )
    if args.campaign_walk:
        editor.fixes = WalkFixes(args.campaign_walk, *(place(f) if f else None
                                                       for f in (args.starts_file, args.ends_file)))
    return editor


def _panel(args, editor, plan):
    from workstation.building import Building
    from workstation.commands._inputs import building_for, building_path_for
    from workstation.io.store import is_remote, place
    from workstation.viz.panel import SurveyPanel

    building_path = building_path_for(args)
    if building_path is not None and is_remote(args.building or place(args.graph)):
        print("note: the building file is in a store: control points place its plans for this "
              "session only; to save them, edit a local copy (--building)", flush=True)  # fmt: skip
        building_path = None
    return SurveyPanel(
        editor, plan, host=args.host, port=args.port,
        building=Building.load(building_path) if building_path else building_for(args),
        building_path=building_path,
    )  # fmt: skip


def _say_unsaved(editor) -> None:
    unsaved = editor.unsaved
    if unsaved:
        g, p = editor.recovery_paths()
        kept = [str(x) for x, what in ((g, "graph"), (p, "parameters")) if what in unsaved]
        print(f"unsaved {' and '.join(unsaved)} kept in {', '.join(kept)}", flush=True)
