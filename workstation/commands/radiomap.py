"""``workstation localize`` and ``merge``: radio maps at work."""

from __future__ import annotations

from pathlib import Path

from workstation.errors import WorkstationError
from workstation.io.store import local_output, output_path, path_or_url, write_via_local


def _matcher(args):
    """The matcher ``--method`` names, with ``--metric`` / ``--k`` where given."""
    from dataclasses import replace

    from workstation.fingerprints.matchers import METHODS

    m = METHODS[args.method]
    if args.metric is not None:
        m = replace(m, metric=args.metric)
    return replace(m, k=args.k) if args.k is not None else m


def _localize(args) -> int:
    from workstation.building.consistency import map_mismatches, refuse
    from workstation.export import write_estimates
    from workstation.fingerprints.devices import one_model
    from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
    from workstation.fingerprints.matchers import name_of
    from workstation.fingerprints.walk_estimates import estimate_walk
    from workstation.session import load_session

    if args.uji:
        return _uji(args)
    if not args.map or not args.session:
        raise WorkstationError("localize needs --map RADIOMAP and --session WALK (or --uji ZIP)")
    maps = read_maps(args.map, args.include_quarantined)
    rm = maps[0] if len(maps) == 1 else Fingerprints.merge(maps)  # (a kind is not merged)
    matcher = _matcher(args)
    if matcher.k > len(rm):
        raise WorkstationError(f"--k {matcher.k}: the map has {len(rm)} reference points")
    session = load_session(args.session)
    session = session.in_frame(rm.frame)
    times, bssids, rss = session.wifi.matrix()
    queries = Fingerprints(times * 0, times * 0, times * 0, bssids, rss, session.frame)

    where = f"{args.session} and the map ({', '.join(map(str, args.map))})"
    found, said = map_mismatches(rm, queries)
    refuse(where, found, args.force, warn=said)
    model = one_model([rm.device, session.metadata.device])
    align = not args.no_align_devices and not model
    index = RadioMapIndex(rm, args.tau, representation=matcher.representation)
    got = estimate_walk(index, session, matcher, align)
    kind = f" (a map of kind {rm.kind})" if rm.kind != "points" else ""
    print(f"{len(rm)} reference points{kind} from {len(args.map)} map(s); {got.scans} scans of "
          f"{args.session}, {int(got.localized.sum())} localized")  # fmt: skip
    for why, n in got.not_used.items():
        print(f"  {n} {why}")
    print(f"  {matcher.words()} ({name_of(matcher)}), tau {args.tau:g} dBm")
    if align:
        print(
            f"  device offset of the walk against the map: {got.device_offset_db:+.1f} dB (removed)"
        )
    elif model and not args.no_align_devices:
        print(f"  the walk and the map: one phone model ({model}), no device offset to remove")
    scored = got.scored()
    _said_errors(scored)
    if args.output:
        write_via_local(args.output, lambda out: write_estimates(got.columns, out, rm.frame))
        print(f"wrote {args.output}: one row per scan (t, x, y, floor, match_distance, aps_heard, "
              "aps_known, localized" + (", lat, lon" if rm.frame is not None else "")
              + (", the truth and error_m" if scored is not None else "") + ")")  # fmt: skip
    return 0


def _uji(args) -> int:
    """``localize --uji ZIP``: every method of the table on UJIIndoorLoc's validation set."""
    from workstation.fingerprints.matchers import DEFAULT
    from workstation.fingerprints.uji import benchmark

    if args.metric is not None or args.k is not None or args.method != DEFAULT:
        print("note: --method, --metric and --k are not used with --uji: the benchmark runs "
              "every method of the table (and plain 1-NN on raw dBm), listed below")  # fmt: skip

    print(
        "UJIIndoorLoc: validation (1,111) against training (19,937); error where building+floor are right"
    )
    for row in benchmark(args.uji):
        print(
            f"  {row['method']:<52} mean {row['mean_m']:6.2f} m  median {row['median_m']:5.2f}  p75 {row['p75_m']:5.2f}  p90 {row['p90_m']:5.2f}  floor {100 * row['floor_accuracy']:5.1f} %  (all rows {row['mean_all_m']:.2f} m)"
        )
    return 0


def _said_errors(scored) -> None:
    """The walk's errors against its ground truth, or that it has none."""
    from workstation.fingerprints.localize import errors

    if scored is None:
        print("  no ground truth in the walk: estimates only")
        return
    e = errors(*scored)
    fa = e["floor_accuracy"]
    print(f"  against the walk's ground truth ({e['queries']} scans):")
    print(f"  floor accuracy  {'–' if fa is None else f'{100 * fa:.1f} %'}")
    if "mean_m" in e:
        print(
            f"  error (floor right): mean {e['mean_m']:.2f} m  median {e['median_m']:.2f}  p75 {e['p75_m']:.2f}  p90 {e['p90_m']:.2f}"
        )
        print(
            f"  all scans, 15 m per wrong floor: mean {e['mean_with_floor_penalty_m']:.2f} m  EvAAL p75 {e['evaal_p75_m']:.2f} m"
        )


def read_maps(paths, include_quarantined: bool):
    """The radio maps, refusing one whose walk is quarantined (pipeline/verdict.py)."""
    from workstation.fingerprints.localize import Fingerprints
    maps = [Fingerprints.read(p) for p in paths]
    held = [(p, m.quarantined) for p, m in zip(paths, maps) if m.quarantined]
    if held and not include_quarantined:
        raise WorkstationError(
            "; ".join(f"{p}: the walk is quarantined ({why})" for p, why in held)
            + " — fix the walk (its summary.json says what to do) and run it again, or pass "
            "--include-quarantined to use it anyway"
        )
    for p, why in held:
        print(f"warning: {p}: quarantined ({why}), included as asked")
    return maps


def _merge_inputs(args) -> tuple[list, list, int]:
    """merge's maps and their paths: a quarantined walk's map is left out and named with its
    reason and what to do (``--include-quarantined`` keeps it); refused only when every map
    is. Also how many were left out."""
    from workstation.fingerprints.localize import Fingerprints

    maps = [Fingerprints.read(p) for p in args.maps]
    built = [f"{p}: a map of kind {m.kind}" for p, m in zip(args.maps, maps) if m.kind != "points"]
    if built:  # a kind is built from the walks' points (fingerprints/kinds.py)
        raise WorkstationError("; ".join(built) + " — merge the walks' maps (kind points) and "
                               "pass --kind to build it from them")  # fmt: skip
    held = [(p, m.quarantined) for p, m in zip(args.maps, maps) if m.quarantined]
    if not held or args.include_quarantined:
        for p, why in held:
            print(f"warning: {p}: quarantined ({why}), included as asked")
        return maps, list(args.maps), 0
    if len(held) == len(maps):
        raise WorkstationError(
            "every map's walk is quarantined (" + "; ".join(f"{p}: {w}" for p, w in held)
            + "): nothing to merge — fix the walks (each summary.json says what to do) and run "
            "them again, or pass --include-quarantined"
        )  # fmt: skip
    for p, why in held:
        print(f"warning: {p}: the walk is quarantined ({why}): left out")
    print("  what to do: fix each (its summary.json says how) and run it again; "
          "--include-quarantined merges them anyway")  # fmt: skip
    keep = [not m.quarantined for m in maps]
    return ([m for m, k in zip(maps, keep) if k], [p for p, k in zip(args.maps, keep) if k],
            len(held))  # fmt: skip


def _merge(args) -> int:
    from workstation.building.consistency import merge_mismatches, refuse
    from workstation.export import write_radiomap
    from workstation.fingerprints.kinds import build, kind_of
    from workstation.fingerprints.localize import Fingerprints
    from workstation.fingerprints.standby import JOIN_M, JOIN_MAX_SIGMA_M

    maps, paths, held = _merge_inputs(args)

    found, said = merge_mismatches(maps, [str(p) for p in paths])
    refuse("the radio maps", found, args.force, warn=said)
    given = len(maps)
    maps, paths = _checked(args, maps, paths)
    points = Fingerprints.merge(maps, align_devices=not args.no_align_devices)
    merged = points if args.kind == "points" else build(args.kind, points)
    write_via_local(args.output, lambda out: write_radiomap(merged.to_frame(), out, merged.frame,
                                                           device=merged.device,
                                                           kind=merged.kind))  # fmt: skip
    out = [f"{held} quarantined"] if held else []
    out += [f"{given - len(maps)} the others cannot reconcile"] if given > len(maps) else []
    print(f"wrote {args.output}: {len(merged)} reference points, {merged.bssids.size} APs from "
          f"{len(maps)} maps" + (f" ({' and '.join(out)} left out)" if out else ""))  # fmt: skip
    if merged is not points:
        print(f"  kind {merged.kind}: {kind_of(merged.kind).words}, from the walks' "
              f"{len(points)} points")  # fmt: skip
    waiting = sum(int(m.on_standby.sum()) for m in maps)
    if waiting:
        joined = len(points) - sum(len(m) for m in maps) + waiting
        print(f"  {joined} of the {waiting} scans on standby (held back for their sigma) joined"
              + (f": no reference point within {JOIN_M:g} m of them" if JOIN_M > 0 else
                 ", each with its sigma (the default matcher weighs 5 neighbours)")
              + (f"; {waiting - joined} with sigma over {JOIN_MAX_SIGMA_M:g} m left out"
                 if joined < waiting else ""))  # fmt: skip
    for path, off in zip(paths, merged.offsets_db):
        print(f"  {path}: device offset {off:+.1f} dB removed")
    if merged.device and not args.no_align_devices:
        print(f"  one phone model ({merged.device}): no device offsets to remove")
    return 0


def _checked(args, maps: list, paths: list) -> tuple[list, list]:
    """The maps as the building's walks place them together (walks/joint.py): each map is one
    walk; each is moved where the others' WiFi and its own placement agree, its points' σ
    from the joint estimate; a walk the others cannot reconcile is named with by how much and
    left out when other walks cover where it went (kept with ``--include-disagreeing``)."""
    from workstation.walks.joint_floors import correct_by_floor as correct

    names = [str(p) for p in paths]  # (a map given twice is two walks' worth of points)
    names = [n if names.count(n) == 1 else f"{n} (#{k + 1})" for k, n in enumerate(names)]
    before = dict(zip(names, maps))
    res = correct(before, align=not args.no_align_devices)
    if args.save or args.connect:  # the walks placed together, seen in Rerun
        from workstation.viz.rerun_joint import save_or_send

        save_or_send(before, res, args.save, args.connect)
        print(f"  the walks placed together: {'wrote ' + str(args.save) if args.save else 'sent to ' + args.connect}")
    keep = [args.include_disagreeing or not res.walks[n].left_out for n in names]
    out = [res.maps[n] if args.include_disagreeing else res.placed(n)
           for n, k in zip(names, keep) if k]  # fmt: skip
    _said_joint(res.walks, args.include_disagreeing, len(maps) - len(out))
    return out, [p for p, k in zip(paths, keep) if k]


def _said_joint(walks: dict, include: bool, left_out: int) -> None:
    """What the joint estimate did, as merge prints it: the walks it moved, those the others
    cannot reconcile (and what to do), the count of each."""
    from workstation.walks.correction import MOVED_M, WHAT_TO_DO

    moved = [w for w in walks.values() if w.moved]
    for w in sorted(moved, key=lambda w: -w.shift_mean_m):  # the likeliest wrong first
        print(f"  {w.words()}")
    odd = [w for w in walks.values() if w.unreconciled]
    for w in odd:
        print(f"warning: {w.words()}{' (kept as asked)' if w.left_out and include else ''}")
    if odd:
        print(f"  what to do: {WHAT_TO_DO}" + ("; --include-disagreeing merges them anyway"
              if any(w.left_out for w in odd) and not include else ""))  # fmt: skip
    linked = sum(w.links for w in walks.values())
    print(f"  {len(walks)} walks placed together ({linked} links between their scans): "
          f"{len(moved)} moved by {MOVED_M:g} m or more, {len(odd)} the others cannot reconcile, "
          f"{left_out} left out")  # fmt: skip


def _positive_int(text: str) -> int:
    import argparse

    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"{v}: at least 1")
    return v


def _tau(text: str) -> float:
    import argparse
    import math

    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number (dBm)") from None
    if not math.isfinite(v) or not -150.0 <= v <= 0.0:
        raise argparse.ArgumentTypeError(f"{text} dBm: a threshold between −150 and 0 dBm")
    return v


def add_parsers(sub) -> None:
    """``localize`` and ``merge``."""
    _localize_parser(sub)
    _merge_parser(sub)


def _localize_parser(sub) -> None:
    from workstation.fingerprints.matchers import DEFAULT, METHODS

    loc = sub.add_parser("localize", help="1-NN/kNN localization of a walk's scans on a radio map")
    loc.add_argument(
        "--map", type=path_or_url, action="append",
        help="radio map CSV/Parquet/GeoJSON, a campaign's radiomap/building=NAME, or a store's "
        "URL (s3://…; repeat to merge several)",
    )
    loc.add_argument(
        "--session", type=Path,
        help="walk whose scans are localized (with ground truth, the errors are printed too)",
    )  # fmt: skip
    loc.add_argument(
        "-o", "--output", type=output_path, metavar="ESTIMATES",
        help="write one row per scan: .csv, .parquet or .geojson (here or at a store's URL)",
    )  # fmt: skip
    loc.add_argument("--method", default=DEFAULT, choices=list(METHODS),
                     help=f"how scans are matched (default {DEFAULT}; 1nn: the paper's; the "
                     "table: docs/reference.md)")  # fmt: skip
    loc.add_argument("--metric", choices=["euclidean", "sorensen"],
                     help="the method's distance, replaced")  # fmt: skip
    loc.add_argument("--k", type=_positive_int, help="the method's neighbours averaged (≥ 1)")
    loc.add_argument(
        "--tau",
        type=_tau,
        default=-90.0,
        help="RSS threshold of the positive representation (dBm, −150 … 0)",
    )
    loc.add_argument(
        "--no-align-devices",
        action="store_true",
        help="do not estimate and remove the walk's RSS offset against the map (phone make)",
    )
    loc.add_argument(
        "--uji", type=Path, metavar="ZIP", help="run the UJIIndoorLoc benchmark instead"
    )
    loc.add_argument(
        "--include-quarantined",
        action="store_true",
        help="use maps of quarantined walks too (refused by default)",
    )
    loc.add_argument(
        "--force",
        action="store_true",
        help="localize even when the walk and the map share no access point or lie km apart",
    )
    loc.set_defaults(func=_localize)


def _merge_parser(sub) -> None:
    from workstation.fingerprints.kinds import DEFAULT_KIND, KINDS

    mg = sub.add_parser("merge", help="merge radio maps of one building")
    mg.add_argument("maps", nargs="+", type=path_or_url)
    mg.add_argument("--kind", default=DEFAULT_KIND, choices=list(KINDS),
                    help="the kind of map built from the walks' points (default "
                    f"{DEFAULT_KIND}: the points themselves; the table: docs/reference.md)")  # fmt: skip
    mg.add_argument("-o", "--output", type=output_path, required=True,
                    help="the merged map here, or at a store's URL (s3://…)")  # fmt: skip
    mg.add_argument(
        "--no-align-devices",
        action="store_true",
        help="keep each map's RSS as recorded (by default each map is one walk, one phone: "
        "its offset is estimated and removed when the maps' phone models differ)",
    )
    mg.add_argument(
        "--include-quarantined",
        action="store_true",
        help="merge maps of quarantined walks too (left out and named by default)",
    )
    mg.add_argument(
        "--force",
        action="store_true",
        help="merge even maps of different sites (geographic frames km apart)",
    )
    mg.add_argument(
        "--include-disagreeing", "--include-unreconciled",
        dest="include_disagreeing",
        action="store_true",
        help="keep the walks the joint estimate cannot reconcile with the others (named, and "
        "left out by default when other walks cover where they went)",
    )
    dest = mg.add_mutually_exclusive_group()
    dest.add_argument(
        "--save", type=local_output, metavar="FILE.rrd",
        help="write a Rerun recording of the walks placed together: each walk's points as its "
        "run placed them, where they went, its links to the other walks",
    )  # fmt: skip
    dest.add_argument("--connect", metavar="URL",
                      help="stream that recording to a running viewer instead")  # fmt: skip
    mg.set_defaults(func=_merge)
