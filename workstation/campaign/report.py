"""A campaign's report: each building's merged radio map (quarantined walks left out), its
leave-one-walk-out figures, ``campaign.json`` and ``campaign.md``."""

from __future__ import annotations

import json
import shlex
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from workstation.campaign.jobs import load_map, load_params
from workstation.campaign.outcome import BuildingReport, CampaignReport, PassClock
from workstation.campaign.records import Records, WalkFiles
from workstation.campaign.report_md import markdown
from workstation.campaign.walk_row import WalkRow
from workstation.export import fingerprints_table
from workstation.fingerprints.kinds import build
from workstation.fingerprints.leave_out import every_nth, leave_one_walk_out
from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
from workstation.fingerprints.matchers import of_params
from workstation.fingerprints.standby import COVER_M, joins
from workstation.graph import LandmarkGraph
from workstation.io.store import is_remote, put_text, read_via_local, remove, store_errors
from workstation.pipeline.start import HandedStart
from workstation.session import load_session
from workstation.stats import error_stats
from workstation.walks.chain import region_arg
from workstation.walks.joint_floors import correct_by_floor
from workstation.walks.start_by_map import rank_by_map


def write_report(
    out: Path, specs, jobs, todo, wall, again: int = 0, busy: tuple[int, float] = (0, 0.0),
    run=None, kind: str = "points", clock: PassClock | None = None, records: Records | None = None,
) -> CampaignReport:
    """``run``: how the building's floors are placed together (walks/joint_floors.py): the
    campaign's workers, or here. ``kind``: the kind of map each building's ``radiomap/`` is
    (fingerprints/kinds.py), built from its walks' merged points."""
    clock = clock or PassClock()
    rows = {w.key: w for w in _walk_rows(jobs, records or Records(out))}
    clock.lap("report_read")
    buildings = {b.name: _building(out, b, jobs, rows, run, kind, clock) for b in specs}
    walks = list(rows.values())
    report = CampaignReport(
        len(walks), sum(w.ok for w in walks), len(todo), again,
        sum(w.quarantined for w in walks), round(wall, 2), buildings, tuple(walks),
        {b.name: _where_starts(b) for b in specs}, {b.name: _where_starts(b, "ends") for b in specs},
        busy[0], round(busy[1], 2), dict(clock.seconds),
    )  # fmt: skip
    put_text(out / "campaign.json", json.dumps(report.to_json(), indent=1, default=str))
    put_text(out / "campaign.md", markdown(report))
    return report


def _walk_rows(jobs, records: Records) -> list[WalkRow]:
    """Per walk, its row of the report: status, error, time, phone and its run's summary."""
    return [replace(WalkRow.of(records.get(j.key)), key=j.key, building=j.building) for j in jobs]


def _building(out, b, jobs, rows: dict[str, WalkRow], run, kind: str,
              clock: PassClock) -> BuildingReport:  # fmt: skip
    """One building's part: its walks placed together, its merged map written, its walks
    localized on the others' map; its walks' rows (in ``rows``) get what the joint estimate
    said, what a held walk would add, the command that opens it, its starts by the map."""
    mine = [w for w in rows.values() if w.building == b.name]
    ok = [w for w in mine if w.ok]
    params = load_params(b.params)
    maps = _placed_together(out, [w for w in ok if not w.quarantined], params, run, clock, rows)
    clock.lap("report_joint")
    ok = [rows[w.key] for w in ok]
    held = [w.key for w in ok if w.quarantined]
    size = _merged_map(out, b, jobs, [rows[k] for k in held], maps, kind, rows)
    clock.lap("report_merged_map")
    files = WalkFiles(out, b.name)
    where = {w.key: (files.path(w.key, "queries.parquet"), w.device) for w in ok
             if files.has(w.key, "queries.parquet")}  # fmt: skip
    qs = {k: load_map(*where[k]) for k in every_nth(list(where))}  # (only those asked)
    # each walk on the others' map, with the building's matcher: one index for them all
    err, ferr, asked = leave_one_walk_out(maps, qs, of_params(params.localize),
                                          params.localize.tau_dbm)  # fmt: skip
    clock.lap("report_leave_one_out")
    return BuildingReport(
        len(mine), len(ok), len(held), *size,
        error_stats(err, ferr) | {"walks_asked": asked} if asked else None,
    )  # fmt: skip


def _merged_map(out, b, jobs, held: list[WalkRow], maps: dict[str, Fingerprints], kind: str,
                rows: dict[str, WalkRow]) -> tuple[int, int]:  # fmt: skip
    """The building's merged map of ``kind`` written (``radiomap/``), what the quarantined walks
    would add to it and the commands that fix them, the ambiguous starts ranked by it (into
    ``rows``); returns its reference points and access points (0, 0: no map)."""
    merged = Fingerprints.merge(list(maps.values()), align_devices=True) if maps else None
    for w in held:
        rows[w.key] = replace(w, map_lacks=_what_it_adds(out, w, merged))
    for key, command in _edit_commands(out, b, jobs, held, merged is not None).items():
        rows[key] = replace(rows[key], edit_command=command)
    if merged is None:
        return 0, 0
    ambiguous = [rows[w.key] for w in held if w.candidates]
    for key, ranked in _rank_starts(b, jobs, ambiguous, merged).items():
        rows[key] = replace(rows[key], **ranked)
    shown = merged if kind == "points" else build(kind, merged)
    del merged
    _write_dataset(shown, out, b.name)
    # (the building's readings are not held through the leave-one-out: #66)
    return len(shown), int(shown.bssids.size)


def _placed_together(out, trusted: list[WalkRow], params, run, clock: PassClock,
                     rows: dict[str, WalkRow]) -> dict[str, Fingerprints]:  # fmt: skip
    """The building's walks correct each other (walks/joint.py): each is placed where the
    others' WiFi and its own run agree; one they cannot reconcile, where others cover where it
    went, is kept out and needs the surveyor like a quarantined walk (its row says so). A
    quarantined walk's points stay out of the merged map until a surveyor fixes it. Returns the
    maps kept, placed; each walk's row in ``rows`` gets what the estimate did to it."""
    maps = {w.key: load_map(out / "walks" / w.key / "map.parquet", w.device) for w in trusted}
    clock.lap("report_load_maps")
    joint = correct_by_floor({k: m for k, m in maps.items() if len(m)}, params.localize.tau_dbm,
                             run=run)  # fmt: skip
    for k, c in joint.walks.items():
        rows[k] = replace(rows[k], joint=c)
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


def _what_it_adds(out: Path, w: WalkRow, merged: Fingerprints | None) -> int | None:
    """A quarantined walk's ``map_lacks``: how many of its scans (reference points and those
    on standby, where its own track puts them) have no point of the building's merged map
    within ``COVER_M`` on their floor — what fixing it would add where the map has nothing
    (None: it left no map). The surveyor fixes those first (campaign.md lists them so)."""
    p = out / "walks" / w.key / "map.parquet"
    if not p.is_file():
        return None
    m = load_map(p)
    if merged is None or not len(merged) or not len(m):
        return len(m)
    xs, ys, fs = (
        np.concatenate([getattr(merged, a), getattr(m, a)]) for a in "x y floor".split()
    )
    mine = np.arange(xs.size) >= len(merged)  # its scans, as on standby against the map
    return int(joins(xs, ys, fs, mine, COVER_M).sum())


def _rank_starts(spec, jobs, walks: list[WalkRow], merged) -> dict[str, dict[str, Any]]:
    """Each walk whose inferred start is ambiguous gets its candidate starts ranked by the
    building's map (``start_by_map``, :func:`..start_by_map.rank_by_map`; or why not:
    ``start_by_map_error``) — per walk, the fields of its row that say it."""
    if not walks:
        return {}

    graph = read_via_local(spec.graph, LandmarkGraph.load)
    params = load_params(spec.params)
    index = RadioMapIndex(merged, params.localize.tau_dbm)
    path = {j.key: j.walk for j in jobs}
    out: dict[str, dict[str, Any]] = {}
    for w in walks:
        after = w.summary.start_after
        try:
            s = read_via_local(path[w.key], load_session)
            cands = list(w.candidates or ())
            among = reach_of(after, graph)
            if among:  # its start was searched within reach of where the walk before ended
                cands = [c for c in cands if c in among] or [w.summary.start_node]
            out[w.key] = {"start_by_map": rank_by_map(s, graph, params, cands, index,
                                                      after.region if after else None)}  # fmt: skip
        except Exception as e:  # noqa: BLE001 - the ranking is a hint; the report goes on
            out[w.key] = {"start_by_map_error": f"{type(e).__name__}: {e}"}
    return out


def reach_of(after: HandedStart | None, graph) -> tuple[str, ...] | None:
    """The landmarks a walk's start was searched among (``start_after`` of its summary), None
    when it was not."""
    return graph.within(*after.region) or None if after else None


def _edit_commands(out: Path, spec, jobs, walks: list[WalkRow], mapped: bool) -> dict[str, str]:
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
    out_: dict[str, str] = {}
    for w in walks:
        fix = ["--campaign-walk", w.name, *files] if files else []
        args = ["workstation", "edit", str(path[w.key]), "--graph", str(spec.graph), *extra]
        after = w.summary.start_after
        if after:  # searched as the campaign did: within reach of where the walk before ended
            args += ["--start-within", region_arg(after.region)]
        out_[w.key] = shlex.join(args + fix)
    return out_


def _where_starts(spec, what: str = "starts") -> str:
    """Where the surveyor gives a single walk's start (or ``what`` = "ends": end), in words."""
    src = getattr(spec, f"{what}_source")
    if src is not None and src.name == f"{what}.yaml":
        return f"{src}"
    return f"{src}, under buildings.{spec.name}.{what}"
