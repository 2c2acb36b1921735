"""The commands that run on one walk — ``info``, ``run``, ``view`` (what they read, and how,
is in :mod:`._inputs`)."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from workstation.pipeline.summary import Quarantine, Summary
from workstation.errors import WorkstationError


def info(args) -> int:
    from workstation.io.store import read_via_local
    from workstation.session import load_session

    s = read_via_local(args.path, load_session)
    # a store's URL as typed, not the copy it was read from
    info = replace(s.info(), path=str(args.path))
    if args.json:
        print(json.dumps(info.to_json(), indent=2))
        return 0
    print(f"{info.path}")
    print(f"  source    {info.source}   device {info.device or '?'}")
    print(f"  duration  {info.duration_s:.1f} s")
    for name, st in info.streams.items():
        rate = "-" if st.rate_hz is None else f"{st.rate_hz:.1f} Hz"
        print(f"  {name:<14}{st.samples:>8} samples  {rate}")
    dt = info.median_scan_interval_s
    iv = "-" if dt is None else f"every {dt:.2f} s"
    print(
        f"  wifi          {info.scans:>8} scans    {info.access_points} APs, {info.readings} readings, {iv}"
    )
    if info.truth_points is None:
        print("  ground truth  none")
    else:
        floors = ", ".join(map(str, info.floors))
        print(f"  ground truth  {info.truth_points:>8} points   floors {floors}")
    if info.skipped_records:
        sk = ", ".join(f"{k} {v}" for k, v in info.skipped_records.items())
        print(f"  skipped       {sk}")
    for w in info.warnings:
        print(f"  warning: {w}")
    return 0


def split(args) -> int:
    """``workstation split WALK --out DIR [--at SECONDS]``: the walk as two session folders,
    cut at SECONDS from its first inertial sample — by default in the middle of its longest
    pause of the inertial sensors (a ``sensor_hole`` quarantine names it), else where a second
    recording begins (``two_clocks``), else where the compass turned alone (``facing_jump``)."""
    from workstation.pipeline.continuity import facing_jump_of
    from workstation.pipeline.verdict import MAX_HOLE_S, sensor_hole
    from workstation.session import load_session
    from workstation.session.native import write_session
    from workstation.session.split import inertial_start, split_at

    s = load_session(args.walk)
    t0 = inertial_start(s)
    if args.at is None:
        hole = sensor_hole([s.accelerometer.t, s.gyroscope.t])
        jump = s.metadata.clock_jump
        facing = None if hole is not None and hole[1] > MAX_HOLE_S or jump else facing_jump_of(s)
        if hole is not None and hole[1] > MAX_HOLE_S:
            at, why = hole[0] + hole[1] / 2, f"in the middle of a {hole[1]:.2f}-s pause"
        elif jump is not None:  # where the second recording begins (session/clocks.py)
            at, why = jump.t - t0, f"where a second recording begins: {jump.what}"
        elif facing is not None:  # the compass turned alone (pipeline/continuity.py)
            at, why = facing[0] - t0, f"where the compass turned {facing[1]:.0f}° alone"
        else:
            raise WorkstationError(f"{args.walk}: its inertial sensors never paused longer than "
                                   f"{MAX_HOLE_S:g} s, it holds no second clock and its compass "
                                   "never turned alone: say where to cut it with --at "
                                   "SECONDS")  # fmt: skip
    else:
        at, why = float(args.at), "as asked"
    name = Path(str(args.walk)).name.removesuffix(".gz").rsplit(".", 1)[0] or "walk"
    dests = [args.out / f"{name}-{i}" for i in (1, 2)]
    there = [d for d in dests if d.exists()]
    if there:
        raise WorkstationError(f"{there[0]} exists: nothing written (give another --out)")
    parts = split_at(s, t0 + at, str(args.walk))
    for d, p in zip(dests, parts):
        write_session(p, d)
        print(f"wrote {d}: {p.duration:.1f} s, {p.wifi.n_scans} WiFi scans")
    print(f"cut at {at:.2f} s ({why}); run each part with its own start (workstation run PART --graph "
          "GRAPH --start LANDMARK, or infer it)")  # fmt: skip
    return 0


def run(args) -> int:
    from workstation.commands._inputs import building_map, load_inputs, start_within
    from workstation.export import write_run
    from workstation.io.store import write_via_local
    from workstation.pipeline import Pipeline
    from workstation.pipeline.run_words import describe_end, what_the_map_did
    from workstation.pipeline.tracking.map_prior import prior_for_walk

    session, graph, params = load_inputs(args)
    # --map is read first: a bad map is refused before anything runs
    ref = building_map(args, graph) if args.map else None
    prior = prior_for_walk(ref, session, params.localize, "--map")  # map_prior.py
    # the start searched within the reach of where the walk before ended (--start-within)
    pipe = Pipeline(session, graph, params, prior=prior, start_within=start_within(args, graph))
    result = pipe.run()
    summary = result.summary(pipe.session, graph)
    if pipe.start_among() and not params.pdr.start_node:
        summary = replace(summary, start_within=tuple(args.start_within))
    held = say_first(args, summary)
    for said in what_the_map_did(summary):  # pipeline/map_prior.py, open_by_map.py
        print(f"  {said}")
    if ref is not None and "start_ambiguous" in summary.reasons:
        said = _by_map(ref, pipe, result, graph, params)
        print(f"  the building's map on its candidate starts: {said}")
    device = session.metadata.device
    write_via_local(args.out, lambda out: write_run(result, summary, out, graph.frame, device))
    keys = [
        "start_node", "steps", "landmarks_detected", "landmarks_matched", "step_length_m", "end_node",
        "segments", "segments_accepted", "reference_points", "trajectory_error_mean_m",
        "trajectory_error_p90_m", "floor_accuracy", "landmark_node_accuracy",
    ]  # fmt: skip
    print(f"wrote {args.out}/: trajectory.csv landmarks.csv segments.csv radiomap.csv summary.json")
    figures = summary.to_json()
    for k in keys:
        if k in figures:
            v = {"end_node": describe_end(summary), "start_node": describe_start(summary)}.get(
                k, figures[k]
            )
            print(f"  {k:<26}{v}")
    scans = summary.scans
    if scans >= 10 and 0 < summary.reference_points < 0.05 * scans:
        print(
            f"warning: only {summary.reference_points} of {scans} scans became reference "
            "points — check the start landmark, the graph and the belief threshold"
        )
    return say_last(held)


def describe_start(summary: Summary) -> str:
    """Where and when the walk starts, in words: "W0 at 27.5 s (inferred: the walk starts where
    the walker sets off after standing)"."""
    from workstation.pipeline.start import HOW as START_HOW
    s = summary.start
    how = "given" if s is None else ("inferred, ambiguous" if s.ambiguous else "inferred")
    when = START_HOW.get(summary.start_time_how, summary.start_time_how)
    return f"{summary.start_node} at {summary.start_time_s} s ({how}: {when})"


def say_first(args, summary: Summary) -> tuple[Quarantine, ...]:
    """What ``run`` and ``view`` say before anything else: what the reader found wrong with the
    input, then a quarantine with its reason and what to do (a wrong walk must not look fine).
    Returns the quarantine."""
    held = summary.quarantine
    for w in summary.input_warnings:
        print(f"warning: {args.session}: {w}")
    for q in held:
        print(f"warning: quarantined — {q.detail}; {q.what_to_do}")
    return held


def say_last(held: Sequence[Quarantine]) -> int:
    """The closing line of a quarantined walk, and the exit status (:data:`EXIT_QUARANTINED`)."""
    from workstation.pipeline.verdict import EXIT_QUARANTINED
    if not held:
        return 0
    print(
        f"quarantined: the points of this walk stay out of merged maps "
        f"({', '.join(q.reason for q in held)}); exit status {EXIT_QUARANTINED}"
    )
    return EXIT_QUARANTINED


def walk_estimates_on(ref, session, params):
    """Every scan of ``session`` localized on the map ``ref`` (fingerprints/walk_estimates.py),
    as ``localize`` does with the parameters' matcher."""
    from workstation.fingerprints.devices import one_model
    from workstation.fingerprints.localize import RadioMapIndex
    from workstation.fingerprints.matchers import of_params
    from workstation.fingerprints.walk_estimates import estimate_walk

    lp = params.localize
    align = lp.align_devices and not one_model([ref.device, session.metadata.device])
    m = of_params(lp)
    index = RadioMapIndex(ref, lp.tau_dbm, representation=m.representation)
    return estimate_walk(index, session, m, bool(align))


def view(args) -> int:
    from workstation.commands._inputs import (
        building_for,
        building_map,
        load_inputs,
        plan_for,
        start_within,
    )
    from workstation.pipeline import Pipeline
    from workstation.pipeline.run_words import describe_end
    from workstation.pipeline.tracking.map_prior import prior_for_walk
    from workstation.viz import layouts
    from workstation.viz.rerun_log import RerunLogger, new_recording
    from workstation.viz.rerun_marks import log_estimates

    session, graph, params = load_inputs(args)
    ref = building_map(args, graph) if args.map else None  # a bad map: refused before the run
    plan = plan_for(args)
    route = _route(args, graph)  # read before anything runs: a bad file stops here
    rec = new_recording()
    baro = session.pressure is not None and len(session.pressure) > 0
    where = _open_recording(rec, args, graph, plan, baro, session)
    prior = prior_for_walk(ref, session, params.localize, "--map")  # map_prior.py
    pipe = Pipeline(session, graph, params, prior=prior, start_within=start_within(args, graph))
    logger = RerunLogger(rec, pipe.session, graph, plan, building_for(args))
    pipe.observers.append(logger)
    result = pipe.run()
    if route:
        logger.log_route(route, graph)
    if ref is not None:  # the walk's scans as the map's WiFi alone places them
        est = walk_estimates_on(ref, pipe.session, params)
        log_estimates(rec, est, result.track)
    # framed on where the run's track went too, now that it is known (a walk placed off, or
    # without a ground truth, opened framed elsewhere)
    rec.send_blueprint(
        layouts.default_blueprint(args.layout, graph, plan, baro, session, result.track)
    )
    rec.flush()
    if not args.save:
        rec.disconnect()
    summ = result.summary(pipe.session, graph)
    held = say_first(args, summ)  # what run says of this walk, view says too (issue #50)
    print(
        f"{summ.steps} steps, {summ.landmarks_matched}/{summ.landmarks_detected} landmarks matched, "
        f"{summ.reference_points} reference points; starts at {describe_start(summ)}, "
        f"ends on {describe_end(summ)}"
    )
    if ref is not None:
        print(f"  {int(est.localized.sum())} of its {est.scans} scans localized on the map "
              "(drawn beside the track)")  # fmt: skip
    print(where)  # on a line of its own: the path copies as it is (no colon glued to it)
    return say_last(held)


def _route(args, graph) -> list[tuple[str, str, str]]:
    """``--route PLAN.json``'s walks as legs (name.i, from, to); none without it."""
    from workstation.survey_plan.output import read_plan_walks

    if not getattr(args, "route", None):
        return []
    walks = read_plan_walks(args.route, graph)
    return [(f"{n}.{i}", u, v) for n, ids in walks.items()
            for i, (u, v) in enumerate(zip(ids[:-1], ids[1:]), 1)]  # fmt: skip


def _open_recording(rec, args, graph, plan, baro, session) -> str:
    """The recording saved to ``--save`` or streamed to ``--connect`` (else to a viewer spawned
    here, with a layout at once); where it went, in words."""
    from workstation.viz import layouts
    from workstation.viz.rerun_log import spawn_viewer

    if args.save:
        Path(args.save).parent.mkdir(parents=True, exist_ok=True)
        rec.save(str(args.save))  # its layout once the run has said where the walk went
        exe = Path(sys.executable).with_name("rerun")
        viewer = (
            "rerun"
            if not exe.exists()
            else os.path.relpath(exe)
            if not os.path.relpath(exe).startswith("..")
            else str(exe)
        )
        return f"saved {args.save} — open it with: {viewer} {args.save}"
    url = args.connect
    if url is None:
        if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise WorkstationError("no display to open a viewer on: use --save FILE.rrd or --connect URL")
        _, url = spawn_viewer()
    # a layout at once (the viewer is open), framed again once the run is done
    rec.connect_grpc(url, default_blueprint=layouts.default_blueprint(
        args.layout, graph, plan, baro, session))  # fmt: skip
    return f"streamed to {url}"


def _by_map(rm, pipe, result, graph, params) -> str:
    """The walk's candidate starts ranked by the building's map (:mod:`..start_by_map`)."""
    from workstation.walks.start_by_map import hint
    cands = [n for n, _ in result.track.start.candidates]
    said = hint(pipe.session, graph, params, cands, rm, pipe.start_within)
    return (said or "no scan to compare") + " (a hint, not a decision: give --start)"
