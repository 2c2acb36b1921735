"""A campaign's report: each building's merged radio map (quarantined walks left out), its
leave-one-walk-out figures, ``campaign.json`` and ``campaign.md``."""

from __future__ import annotations

import json
import shlex
import tempfile
from pathlib import Path

import numpy as np

from workstation.campaign.jobs import load_map, load_params, walk_summary
from workstation.campaign.outcome import BuildingReport, CampaignReport, PassClock
from workstation.campaign.records import Records, WalkFiles
from workstation.export import fingerprints_table
from workstation.fingerprints.kinds import build
from workstation.fingerprints.leave_out import every_nth, leave_one_walk_out
from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
from workstation.fingerprints.matchers import of_params
from workstation.fingerprints.standby import COVER_M, joins
from workstation.graph import LandmarkGraph
from workstation.io.store import is_remote, put_text, read_via_local, remove, store_errors
from workstation.session import load_session
from workstation.stats import error_stats
from workstation.walks.chain import region_arg, region_of
from workstation.walks.joint import WHAT_TO_DO
from workstation.walks.joint_floors import correct_by_floor
from workstation.walks.start_by_map import MapRanking, describe, rank_by_map


def write_report(
    out: Path, specs, jobs, todo, wall, again: int = 0, busy: tuple[int, float] = (0, 0.0),
    run=None, kind: str = "points", clock: PassClock | None = None, records: Records | None = None,
) -> CampaignReport:
    """``run``: how the building's floors are placed together (walks/joint_floors.py): the
    campaign's workers, or here. ``kind``: the kind of map each building's ``radiomap/`` is
    (fingerprints/kinds.py), built from its walks' merged points."""
    clock = clock or PassClock()
    walks = _walk_rows(jobs, records or Records(out))
    clock.lap("report_read")
    buildings = {b.name: _building(out, b, jobs, walks, run, kind, clock) for b in specs}
    report = CampaignReport(
        len(walks), sum(w["status"] == "ok" for w in walks), len(todo), again,
        sum(bool(w.get("quarantine")) for w in walks), round(wall, 2), buildings, tuple(walks),
        {b.name: _where_starts(b) for b in specs}, {b.name: _where_starts(b, "ends") for b in specs},
        busy[0], round(busy[1], 2), dict(clock.seconds),
    )  # fmt: skip
    doc = report.to_json()
    put_text(out / "campaign.json", json.dumps(doc, indent=1, default=str))
    put_text(out / "campaign.md", _markdown(doc))
    return report


def _walk_rows(jobs, records: Records) -> list[dict]:
    """Per walk, its row of the report: status, error, time, phone and its run's summary."""
    walks = []
    for j in jobs:
        meta = records.get(j.key)
        walks.append({"key": j.key, "building": j.building, "status": meta.get("status", "missing"),
                      "error": meta.get("error"), "seconds": meta.get("seconds"),
                      **({"retry": True} if meta.get("retry") else {}),
                      "device": meta.get("device") or "",
                      **(meta.get("summary") or {})})  # fmt: skip
        if meta.get("start_shared"):
            walks[-1]["start_shared_with"] = meta["start_shared"]["with"]
        if "start_ambiguous" in walk_summary(meta).reasons:
            walks[-1]["candidates"] = [
                n for n, _ in meta.get("start_inference", {}).get("candidates", [])
            ]
    return walks


def _building(out, b, jobs, walks: list[dict], run, kind: str, clock: PassClock) -> BuildingReport:
    """One building's part: its walks placed together, its merged map written, its walks
    localized on the others' map; its walks' rows get what the joint estimate said."""
    ok = [w for w in walks if w["building"] == b.name and w["status"] == "ok"]
    params = load_params(b.params)
    maps = _placed_together(out, [w for w in ok if not w.get("quarantine")], params, run, clock)
    clock.lap("report_joint")
    entry = {"walks": sum(w["building"] == b.name for w in walks), "walks_ok": len(ok),
             "walks_quarantined": sum(bool(w.get("quarantine")) for w in ok)}  # fmt: skip
    entry |= _merged_map(out, b, jobs, ok, maps, kind)
    clock.lap("report_merged_map")
    files = WalkFiles(out, b.name)
    where = {w["key"]: (files.path(w["key"], "queries.parquet"), w["device"]) for w in ok
             if files.has(w["key"], "queries.parquet")}  # fmt: skip
    qs = {k: load_map(*where[k]) for k in every_nth(list(where))}  # (only those asked)
    # each walk on the others' map, with the building's matcher: one index for them all
    err, ferr, asked = leave_one_walk_out(maps, qs, of_params(params.localize),
                                          params.localize.tau_dbm)  # fmt: skip
    if asked:
        entry["leave_one_out"] = error_stats(err, ferr) | {"walks_asked": asked}
    clock.lap("report_leave_one_out")
    return BuildingReport.from_json(entry)


def _merged_map(out, b, jobs, ok: list[dict], maps: dict[str, Fingerprints], kind: str) -> dict:
    """The building's merged map of ``kind`` written (``radiomap/``), what the quarantined walks
    would add to it and the commands that fix them, the ambiguous starts ranked by it; returns
    its size."""
    merged = Fingerprints.merge(list(maps.values()), align_devices=True) if maps else None
    held = [w for w in ok if w.get("quarantine")]
    _what_they_add(out, held, merged)
    _edit_commands(out, b, jobs, held, merged is not None)
    if merged is None:
        return {}
    _rank_starts(b, jobs, [w for w in ok if w.get("candidates")], merged)
    shown = merged if kind == "points" else build(kind, merged)
    del merged
    _write_dataset(shown, out, b.name)
    # (the building's readings are not held through the leave-one-out: #66)
    return {"reference_points": len(shown), "access_points": int(shown.bssids.size)}


def _placed_together(out, trusted: list[dict], params, run,
                     clock: PassClock) -> dict[str, Fingerprints]:  # fmt: skip
    """The building's walks correct each other (walks/joint.py): each is placed where the
    others' WiFi and its own run agree; one they cannot reconcile, where others cover where it
    went, is kept out and needs the surveyor like a quarantined walk (its row says so). A
    quarantined walk's points stay out of the merged map until a surveyor fixes it. Returns the
    maps kept, placed."""
    maps = {w["key"]: load_map(out / "walks" / w["key"] / "map.parquet", w["device"])
            for w in trusted}  # fmt: skip
    clock.lap("report_load_maps")
    joint = correct_by_floor({k: m for k, m in maps.items() if len(m)}, params.localize.tau_dbm,
                             run=run)  # fmt: skip
    by_key = {w["key"]: w for w in trusted}
    for k, c in joint.walks.items():
        by_key[k]["joint"] = c.to_dict()
        if c.left_out:
            by_key[k]["quarantine"] = [{"reason": "unreconciled", "detail": c.words(),
                                        "what_to_do": WHAT_TO_DO}]  # fmt: skip
    return joint.kept()


BLOCK_BYTES = 64 << 20  # a building's merged map is written this many bytes of RSS at a time


def _write_dataset(fp: Fingerprints, out, name: str) -> None:
    """The building's merged map as ``radiomap/building=NAME/floor=…/`` Parquet, replacing
    the one before; into a store as the same files, written here first and then uploaded."""
    part = out / "radiomap" / f"building={name}"
    remove(part, recursive=True)
    if not is_remote(out):
        _write_parts(fp, out / "radiomap", name)
        return
    with tempfile.TemporaryDirectory(prefix="workstation-map-") as tmp:
        _write_parts(fp, Path(tmp), name)
        with store_errors(part):
            part.fs.put(f"{tmp}/building={name}/", part.path + "/", recursive=True)


def _write_parts(fp: Fingerprints, root: Path, name: str) -> None:
    """``BLOCK_BYTES`` of rows at a time, each block a file per floor (``part-KKKKK-I``, read
    back in that order): an Arrow table of the whole map, then the copies partitioning made of
    it, were two more copies of a building's readings (0.7 GB each at 2,500 walks: the client
    of a 10,000-walk campaign, issue #66). The frame, phone model and kind are in each part's
    metadata (map_read.py reads them)."""
    import pyarrow.parquet as pq

    rows = max(1, BLOCK_BYTES // (8 * max(1, fp.bssids.size)))
    for k, lo in enumerate(range(0, max(len(fp), 1), rows)):
        table = fingerprints_table(fp.subset(slice(lo, lo + rows)), name)
        pq.write_to_dataset(table, root, partition_cols=["building", "floor"],
                            basename_template=f"part-{k:05d}-{{i}}.parquet")  # fmt: skip


def _what_they_add(out: Path, held: list[dict], merged: Fingerprints | None) -> None:
    """Per quarantined walk, ``map_lacks``: how many of its scans (reference points and those
    on standby, where its own track puts them) have no point of the building's merged map
    within ``COVER_M`` on their floor — what fixing it would add where the map has nothing.
    The surveyor fixes those first (campaign.md lists them so)."""
    for w in held:
        p = out / "walks" / w["key"] / "map.parquet"
        if not p.is_file():
            continue
        m = load_map(p)
        if merged is None or not len(merged) or not len(m):
            w["map_lacks"] = len(m)
            continue
        xs, ys, fs = (
            np.concatenate([getattr(merged, a), getattr(m, a)]) for a in "x y floor".split()
        )
        mine = np.arange(xs.size) >= len(merged)  # its scans, as on standby against the map
        w["map_lacks"] = int(joins(xs, ys, fs, mine, COVER_M).sum())


def _rank_starts(spec, jobs, walks: list[dict], merged) -> None:
    """Each walk whose inferred start is ambiguous gets its candidate starts ranked by the
    building's map (``start_by_map``: [landmark, median m], :func:`..start_by_map.rank_by_map`)."""
    if not walks:
        return

    graph = read_via_local(spec.graph, LandmarkGraph.load)
    params = load_params(spec.params)
    index = RadioMapIndex(merged, params.localize.tau_dbm)
    path = {j.key: j.walk for j in jobs}
    for w in walks:
        try:
            s = read_via_local(path[w["key"]], load_session)
            region, cands = region_of(w.get("start_after")), w["candidates"]
            among = reach_of(w.get("start_after"), graph)
            if among:  # its start was searched within reach of where the walk before ended
                cands = [c for c in cands if c in among] or [w["start_node"]]
            got = rank_by_map(s, graph, params, cands, index, region)
            w["start_by_map"], w["start_near_by_map"] = list(got.ranked), got.near
            w["start_near_floor_by_map"] = got.near_floor
            w["start_by_map_margin_ll"] = got.margin_ll
        except Exception as e:  # noqa: BLE001 - the ranking is a hint; the report goes on
            w["start_by_map_error"] = f"{type(e).__name__}: {e}"


def reach_of(after: dict | None, graph) -> tuple[str, ...] | None:
    """The landmarks a walk's start was searched among (``start_after`` of its summary:
    :meth:`workstation.walks.chain.Handover.to_dict`), None when it was not."""
    region = region_of(after)
    return graph.within(*region) or None if region else None


def _edit_commands(out: Path, spec, jobs, walks: list[dict], mapped: bool) -> None:
    """Each walk's command that opens it in the panel (``edit_command``) — on the building's
    merged map when there is one (``mapped``): an ambiguous start's likeliest candidates
    ringed on the plan, "Start here" or "End here" to fix it."""
    path = {j.key: j.walk for j in jobs}
    extra = ["--params", str(spec.params)] if spec.params else []
    if spec.building:  # the plan images under the walk (issue #50 item 9: left out)
        extra += ["--building", str(spec.building)]
    if mapped:
        extra += ["--map", str(out / "radiomap" / f"building={spec.name}")]
    files = []  # a folder campaign's starts.yaml / ends.yaml: the panel writes the fix there
    for what in ("starts", "ends"):
        src = getattr(spec, f"{what}_source")
        if src is not None and src.name == f"{what}.yaml":
            files += [f"--{what}-file", str(src)]
    for w in walks:
        fix = ["--campaign-walk", w["key"].split("/", 1)[1], *files] if files else []
        args = ["workstation", "edit", str(path[w["key"]]), "--graph", str(spec.graph), *extra]
        region = region_of(w.get("start_after"))
        if region:  # searched as the campaign did: within reach of where the walk before ended
            args += ["--start-within", region_arg(region)]
        w["edit_command"] = shlex.join(args + fix)


def _where_starts(spec, what: str = "starts") -> str:
    """Where the surveyor gives a single walk's start (or ``what`` = "ends": end), in words."""
    src = getattr(spec, f"{what}_source")
    if src is not None and src.name == f"{what}.yaml":
        return f"{src}"
    return f"{src}, under buildings.{spec.name}.{what}"


def _markdown(r: dict) -> str:
    L = [
        "# Campaign",
        "",
        f"{r['walks']} walks, {r['walks_ok']} processed, {r['walks'] - r['walks_ok']} failed; "
        f"{r['run_now']} run this time"
        + (
            f", {r['run_again_with_map']} again with the map of their building's other walks"
            if r.get("run_again_with_map")
            else ""
        )
        + f" in {r['wall_seconds']} s"
        + (f" ({r['runs']} walk runs, {r['busy_seconds']} s of the workers' time)"
           if r.get("runs") else "")
        + ". "
        f"{r.get('walks_quarantined', 0)} walks need the surveyor: their points are kept out "
        "of the merged maps (below). LOO: each walk's scans (at most 200 walks a building, every "
        "n-th) localized on the map of the others, with the building's matcher.",
        "",
        "| building | walks | ran | in the map | need the surveyor | reference points | APs | LOO mean, floor right (m) | with floor penalty (m) | floor accuracy |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, b in r["buildings"].items():
        lo = b.get("leave_one_out") or {}
        L.append(
            f"| {name} | {b['walks']} | {b['walks_ok']} | {b['walks_ok'] - b['walks_quarantined']} | "
            f"{b['walks_quarantined']} | {b.get('reference_points', 0)} | "
            f"{b.get('access_points', 0)} | {lo.get('mean_m', '–')} | "
            f"{lo.get('mean_with_floor_penalty_m', '–')} | {lo.get('floor_accuracy', '–')} |"
        )
    L += ["", "| walk | status | start | steps | matched | ends on | RPs | error at fixes (m) | seconds |",
          "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    L += [_walk_line(w) for w in r["per_walk"]]
    held = [w for w in r["per_walk"] if w["status"] == "ok" and w.get("quarantine")]
    held.sort(key=lambda w: -w.get("map_lacks", 0))  # (stable: the walks' order within ties)
    if held:
        L += ["", "## Needs the surveyor", "",
              "These walks ran, but the pipeline is unsure of them: their reference points are "
              "not in the merged map until the walk is fixed and run again. First the walks "
              f"whose scans lie where the building's map has no point within {COVER_M:g} m (as "
              "their own track places them): fixing those adds most.", "",
              "| walk | why | scans where the map has none | what to do |",
              "|---|---|---|---|"]  # fmt: skip
        L += [f"| {w['key']} | {q['detail']} | {w.get('map_lacks', '–')} | {_what_to_do(r, w, q)} |"
              for w in held for q in w["quarantine"]]  # fmt: skip
    return "\n".join(L) + "\n"


def _walk_line(w: dict) -> str:
    """A walk's row of campaign.md's table of walks."""
    status = w["status"] if w["status"] == "ok" else f"{w['status']}: {w.get('error')}"
    if w["status"] == "ok" and w.get("quarantine"):
        status = "needs the surveyor"
    start = w.get("start_node") or "–"
    if w.get("start_shared_with"):
        start += " (decided with " + ", ".join(w["start_shared_with"]) + ")"
    if w.get("start_after"):
        h = w["start_after"]
        start += (f" (within {h['reach_m']:g} m of where {h['walk_before']} ended, "
                  f"{h['gap_s']:g} s before)")  # fmt: skip
    return (
        f"| {w['key']} | {status} | {start} | {w.get('steps', '–')} | {w.get('landmarks_matched', '–')} "
        f"| {_ends_on(w)} | {w.get('reference_points', '–')} | {w.get('fix_error_mean_m', '–')} | {w.get('seconds')} |"
    )


def _what_to_do(r: dict, w: dict, q: dict) -> str:
    """What the surveyor does about one reason a walk needs them, in this campaign's files."""
    todo = q["what_to_do"]
    if q["reason"] == "start_ambiguous":
        return _start_fix(w, r.get("starts_files", {}).get(w["building"], "starts.yaml"))
    if q["reason"] in ("nothing_matched", "end_far"):
        where = r.get("ends_files", {}).get(w["building"], "ends.yaml")
        name = w["key"].split("/", 1)[1]
        todo += f"; in this campaign the walk's end goes in {where} ({name}: LANDMARK)"
        if w.get("edit_command"):
            writes = (" — 'End here' there writes it"
                      if " --ends-file " in w["edit_command"] else "")  # fmt: skip
            todo += f"; to look at it: `{w['edit_command']}`{writes}"
    return todo


def _ends_on(w: dict) -> str:
    """Where a walk's end was closed (walk_end.py) and how tightly: "L124 (σ 0.9 m)"; a closed
    end within ``state.END_CHECK_M`` checks a walk that matched no detection, so "matched 0"
    with "ok" is read beside it."""
    how = w.get("end_how")
    if how in ("given", "given_far"):
        return f"{w.get('end_node')} (given" + (
            "; the sensors end it elsewhere)" if how == "given_far" else ")"
        )
    if how == "closed" and w.get("end_node"):
        sd = w.get("end_sigma_m")
        return f"{w['end_node']} (σ {sd:g} m)" if sd is not None else str(w["end_node"])
    return {"at_last_match": "last match", None: "–"}.get(how, "open")


def _start_fix(w: dict, starts_file: str) -> str:
    """What to do for a campaign walk whose start is ambiguous: where to give it, and what the
    building's map says of its candidates (:mod:`..start_by_map`)."""
    name = w["key"].split("/", 1)[1]
    cmd = w.get("edit_command") or "workstation edit"
    ringed = "the map's likeliest starts are ringed, " if " --map " in cmd else ""
    if " --starts-file " in cmd:  # the panel writes the fix
        out = (f"check the start on the plan (`{cmd}`: {ringed}'Start here' on the right "
               f"landmark shows the walk from it and writes `{name}: LANDMARK` to "
               f"{starts_file}), then run the campaign again")  # fmt: skip
    else:
        out = (f"check the start on the plan (`{cmd}`: {ringed}'Start here' shows the walk from "
               f"one), then add `{name}: LANDMARK` to {starts_file} and run the campaign again")  # fmt: skip
    said = describe(MapRanking.of(w.get("start_by_map"), w.get("start_near_by_map"),
                                  w.get("start_near_floor_by_map"),
                                  w.get("start_by_map_margin_ll")))  # fmt: skip
    if w.get("start_by_map"):
        out += (". Its candidate starts by the building's map (likeliest first; the median "
                "distance between where each places its scans and where the map's WiFi puts "
                "them; a hint, not a decision): " + said)  # fmt: skip
    elif w.get("candidates"):
        out += ". Its candidate starts: " + ", ".join(w["candidates"])
    return out
