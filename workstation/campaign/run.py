"""A campaign run (:mod:`workstation.campaign`): plan the walks' jobs, run what changed, the
passes that run walks again, the report."""

from __future__ import annotations

import hashlib
import json
import re
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from workstation.campaign.execute import Executor
from workstation.campaign.handover import handed_starts
from workstation.campaign.jobs import (
    WalkJob,
    code_digest,
    file_digest,
    first_maps,
    load_params,
    mark_done,
    put_maps,
)
from workstation.campaign.layout import BuildingSpec, load_campaign
from workstation.campaign.lock import CampaignLock
from workstation.campaign.outcome import CampaignReport, PassClock
from workstation.campaign.records import Records, WalkFiles, summary_text
from workstation.campaign.report import write_report
from workstation.campaign.shared_pass import shared_starts
from workstation.campaign.starts import check_starts
from workstation.campaign.walk_result import WalkResult
from workstation.errors import InputError
from workstation.fingerprints.leave_out import every_nth
from workstation.io.atomic import outside, sweep_leftovers
from workstation.io.store import (
    is_remote,
    place,
    put_text,
    store_errors,
)
from workstation.pipeline.verdict import reasons

STATE_EVERY_S = 1.0  # how often the first pass commits state.json (at most)

def plan_jobs(specs: list[BuildingSpec]) -> list[WalkJob]:
    code = code_digest()
    jobs = []
    for b in specs:
        stamp = file_digest(b.graph)
        shared = "|".join([stamp, *(file_digest(p) for p in (b.params, b.building))])
        keys = walk_keys(b.walks)
        given = check_starts(b, keys)  # the surveyor's start of single walks (starts.yaml)
        ends = check_starts(b, keys, "ends")  # … and where they ended (ends.yaml)
        for w, name in zip(b.walks, keys):
            start, end = given.get(name, b.start), ends.get(name)
            digest = f"{file_digest(w)}|{shared}|{code}|{start}|{end}"
            jobs.append(
                WalkJob(b.name, w, b.graph, b.params, start, f"{b.name}/{name}", digest, end=end,
                        graph_stamp=stamp)
            )
    return jobs


def _is_dir(p: Path) -> bool:
    try:
        return p.is_dir()
    except OSError:  # a name too long for the file system: not a folder (the run says why)
        return False


def walk_keys(walks) -> list[str]:
    """One folder name per walk, unique within its building: the file's name without its
    extension (a.txt and a.txt.gz → a), characters other than letters, digits, '.', '_' and '-' as '_';
    walks that would share one (walk.txt in two folders, a.txt and a.csv) get ~2, ~3… in the
    order listed — two walks once got one key and one of them was lost."""
    out: list = []
    seen: dict[str, int] = {}
    for w in walks:
        name = w.name[:-3] if w.name.endswith(".gz") else w.name
        stem = Path(name).stem if not _is_dir(w) else name
        key = re.sub(r"[^A-Za-z0-9._-]", "_", stem).lstrip(".")[:100] or "walk"
        n = seen.get(key, 0) + 1
        seen[key] = n
        out.append(key if n == 1 else f"{key}~{n}")
    return out


def run_campaign(
    campaign: str | Path,
    out: str | Path,
    scheduler: str | None = None,
    workers: int | None = None,
    force: bool = False,
    say: Callable[[str], None] = print,
    progress: Callable[..., None] | None = None,
    kind: str = "points",
) -> CampaignReport:
    """Run what changed; ``say`` gets messages, ``progress(i, n, what)`` each finished walk
    (without it every walk is also a line through ``say``); ``kind``: the kind of map each
    building's ``radiomap/`` is (fingerprints/kinds.py)."""
    specs = load_campaign(campaign)
    out = place(out, cached=False)
    if not is_remote(out) and Path(out).exists() and not Path(out).is_dir():
        # a file or a pipe where the output folder goes (issue #67 item 5: "free the space")
        raise InputError(out, "is not a folder: --out is the folder the campaign's results go "
                         "to (made when missing) — give a folder, or move this away")  # fmt: skip
    with store_errors(out), CampaignLock(out, say) as lock:
        return _run(specs, out, lock, scheduler, workers, force, say, progress, kind)


def _run(specs, out, lock, scheduler, workers, force, say, progress,
         kind: str = "points") -> CampaignReport:  # fmt: skip
    if not is_remote(out):
        out.mkdir(parents=True, exist_ok=True)
        swept = sweep_leftovers(out, recursive=True, own=True)  # a killed run's half-written
        if swept:
            say(f"removed {len(swept)} temporary file(s) a killed run had left in {out}")
    state_path = out / "state.json"
    state = json.loads(state_path.read_text()) if state_path.is_file() and not force else {}
    jobs = plan_jobs(specs)
    if is_remote(out):  # its workers write the walks' maps to the store themselves
        jobs = [replace(j, out=out, token=lock.token) for j in jobs]
    else:
        _check_inside(out, jobs)
    todo = [j for j in jobs if force or state.get(j.key) != j.digest]
    say(
        f"{len(jobs)} walks in {len(specs)} buildings; {len(todo)} to run, {len(jobs) - len(todo)} unchanged"
    )
    t0 = time.perf_counter()
    busy = [0, 0.0]  # walk runs, their own seconds

    def counted(execute):
        def run(batch):
            for res in execute(batch):
                busy[0] += 1
                busy[1] += float(res.seconds or 0.0)
                yield res

        return run

    clock = PassClock()  # (from before the workers start)
    with Executor(scheduler, workers, say) as execute:
        clock.lap("start_workers")
        records = Records(out)  # every walk's summary.json, read once (issue #66)
        again = _passes(out, specs, jobs, todo, state, state_path, force, say, progress,
                        counted(execute), lock, clock, records)  # fmt: skip
        wall = time.perf_counter() - t0
        # the building's floors placed together on the workers that ran the walks (if any)
        report = write_report(out, specs, jobs, todo, wall, len(again),
                              (int(busy[0]), busy[1]), run=execute.map, kind=kind,
                              clock=clock, records=records)  # fmt: skip
    say(f"wrote {out}/campaign.json, campaign.md and radiomap/ ({wall:.1f} s)")
    return report


def _passes(out, specs, jobs, todo, state, state_path, force, say, progress, execute,
            lock, clock: PassClock, records: Records) -> list:  # fmt: skip
    """The walks that changed, then the three passes that run walks again (starts shared by
    walks that stood together, the building's map, handed-over starts); ``todo`` grows by the
    jobs run again. Returns the map pass's walks."""
    saved = [0.0]

    def commit(now: bool = False) -> None:
        """``state.json`` after the walks' files: what it lists is whole. At most every
        ``STATE_EVERY_S`` (10,000 walks rewrote it 10,000 times, 6 GB into a store): a kill
        redoes at most that second's walks."""
        if now or time.monotonic() - saved[0] >= STATE_EVERY_S:
            put_text(state_path, json.dumps(state, indent=1))
            saved[0] = time.monotonic()
            lock.beat()

    try:
        for i, res in enumerate(execute(todo), 1):
            records.keep(res.key, _store(out, res))
            # a failure is a result too: not re-run until its inputs change (or --force) —
            # unless its input could not be read: tried again next time (jobs.unreadable)
            mark_done(state, res.key, res.digest, res)
            commit()
            mark = _mark(res)
            if progress is not None:
                if not res.ok:
                    say(f"  {res.key}: {mark}")
                # a quarantined walk ran, but is not "ok": said as it is (issue #64 item 7)
                progress(i, len(todo), f"{res.key}: {mark}", phase="walks")
            else:
                say(f"  [{i}/{len(todo)}] {res.key}: {mark} ({res.seconds or 0.0:.1f} s)")
        commit(now=True)
        clock.lap("walks")
        # the passes that run walks again commit as they go too (#66: a kill lost the map pass)
        todo += shared_starts(specs, jobs, state, force, say, execute, records,
                              lambda res: records.keep(res.key, _store(out, res)), commit)
        clock.lap("shared_starts")
        again = _map_pass(out, specs, jobs, state, force, say, execute, records, commit)
        clock.lap("map_pass")
        # after the map pass: where each walk before ended as its final run says (the map pass
        # reads only walks whose start was given, so nothing here changes its input)
        todo += handed_starts(out, specs, jobs, state, force, say, execute,
                              lambda _out, j: records.get(j.key),
                              lambda o, res: records.keep(res.key, _store(o, res)), commit)
        clock.lap("handed_starts")
    finally:  # Ctrl+C too: what is stored is kept
        commit(now=True)
    return again


def _mark(res: WalkResult) -> str:
    if not res.ok:
        again = " (could not be read: tried again on the next run)" if res.retry else ""
        return f"FAILED: {res.error}{again}"
    held = reasons(res.summary)
    return f"quarantined ({held})" if held else "ok"


# ---- each walk again, with the map of the building's other walks --------------------------
MAX_PRIOR_WALKS = 200  # the first-run maps a building's map pass uses at most (every n-th)


def _map_pass(out: Path, specs, jobs, state: dict, force: bool, say, execute,
              records: Records, commit=lambda now=False: None) -> list:  # fmt: skip
    """Per building, each walk whose start is given (not inferred: the start is never the
    map's) runs again with the first runs' maps of (up to ``MAX_PRIOR_WALKS`` of) the
    building's other walks — quarantined ones left out — as evidence on its chain of matches
    (:mod:`..pipeline.map_prior`; ``pdr.map_weight`` 0: off). It runs again when any of those
    maps changed. Returns the jobs run."""
    runs: dict[str, WalkJob] = {}
    for b in specs:
        if load_params(b.params).pdr.map_weight > 0:  # (one file a building: read once)
            runs |= _map_jobs(out, b.name, [j for j in jobs if j.building == b.name], records)
    runs = {k: j for k, j in runs.items() if force or state.get(k + "@map") != j.digest}
    if runs:
        say(f"  {len(runs)} walks again with the map of their building's other walks")
    for res in execute(list(runs.values())):
        job = runs.get(res.key)
        if job is None:
            continue
        records.keep(res.key, _store(out, res))  # (then the state: only what is stored)
        mark_done(state, job.key + "@map", job.digest, res)
        commit()
    return list(runs.values())


def _map_jobs(out: Path, building: str, bj: list[WalkJob], records: Records) -> dict[str, WalkJob]:
    """One building's jobs of the map pass (:func:`_map_pass`), its first-run maps written."""
    metas = {j.key: records.get(j.key) for j in bj}
    files = WalkFiles(out, building)
    firsts = {j.key: files.path(j.key, "first.parquet") for j in bj
              if not metas[j.key].start_inference and files.has(j.key, "first.parquet")}
    want = [j for j in bj if metas[j.key].ok
            and not metas[j.key].start_inference and j.start is not None
            and set(firsts) - {j.key}]  # fmt: skip
    if not want:
        return {}
    # at most MAX_PRIOR_WALKS of them (every n-th): each job reads and indexes this map, so
    # a bounded map keeps the pass linear in walks (a crowd's thousands a building)
    firsts = {k: firsts[k] for k in every_nth(sorted(firsts), MAX_PRIOR_WALKS)}
    # (one digest of them all: a walk's own map changing changes its own digest anyway)
    seen = _hash("".join(k + files.digest(k, "first.parquet") for k in sorted(firsts)))
    merged, stamp = first_maps(out / "walks" / building / "first_maps.parquet", firsts)
    return {j.key: replace(j, prior_map=merged, prior_stamp=stamp, digest=f"{j.digest}|map:{seen}")
            for j in want}  # fmt: skip


def _hash(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _check_inside(out: Path, jobs) -> None:
    """Refuse, before anything is written, a symbolic link in the campaign's folder that leads
    out of it (every name inside is ours: a link there steers our writes elsewhere)."""
    names = ["state.json", "campaign.json", "campaign.md", "radiomap", "walks"]
    paths = [out / n for n in names]
    for j in jobs:
        d = out / "walks" / j.key
        paths += [d, d / "summary.json", d / "map.parquet", d / "queries.parquet",
                  d / "first.parquet", d.parent / "first_maps.parquet"]  # fmt: skip
    bad = outside(out, paths)
    if bad is not None:
        raise InputError(
            bad,
            f"leads out of the campaign's folder {out} (a symbolic link): our outputs are not "
            "written through it; remove the link, or give another --out",
        )


def _store(out: Path, res: WalkResult) -> str:
    """A walk's result: its Parquet (unless its worker wrote them to the store), then its
    ``summary.json``; returns that file's text."""
    d = out / "walks" / res.key
    if not is_remote(d):
        d.mkdir(parents=True, exist_ok=True)
    if not res.stored:
        put_maps(d, res.maps)  # Parquet made by the worker (jobs.map_bytes)
    text = summary_text(res)
    put_text(d / "summary.json", text)
    return text
