"""One walk of a campaign, run where a worker runs it: a pure function from file paths to a small
picklable result (summary, accepted reference points, query scans at the ground truth). Errors
are results too — one bad walk never stops the others."""

from __future__ import annotations

import hashlib
import io
import json
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import Any

import numpy as np

import workstation
from workstation.building.consistency import mismatches
from workstation.campaign.lock import still_holds
from workstation.campaign.walk_result import MAP_FILES, InferredStart, WalkResult
from workstation.errors import InputError, Unreadable
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.io.map_read import FIXED_COLUMNS, META_KEY
from workstation.io.store import (
    etag,
    get_bytes,
    is_remote,
    place,
    put_bytes,
    read_via_local,
    remove,
)
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import HandedStart, resolve_start
from workstation.pipeline.summary import Summary
from workstation.pipeline.tracking.map_prior import prior_for_walk
from workstation.session import load_session
from workstation.walks.chain import wall_clock, where_ended
from workstation.walks.shared_start import stand_fingerprint

WALK_COLUMN = "walk"  # whose row it is, in a building's first-run maps (campaign._map_pass)


@dataclass(frozen=True)
class WalkJob:
    building: str
    walk: Path
    graph: Path
    params: Path | None
    start: str | None
    key: str  # building/walk name
    digest: str  # of every input and the code
    # the first runs' maps of the building's walks, one file (a ``walk`` column says whose):
    # where the others put this walk's scans weighs in choosing its chain of matches
    # (pipeline/map_prior.py); None on the first run
    prior_map: Path | None = None
    end: str | None = None  # the landmark the surveyor says the walk ended on (ends.yaml)
    # an inferred start searched only within reach of where the walk recorded just before
    # ended (walks/chain.py: ``Handover.handed``)
    after: HandedStart | None = None
    # a campaign whose output is in a store (issue #54): the worker writes the walk's Parquet
    # there itself while its run holds the lock (``token``), and returns only the summary
    out: Any = None
    token: str = ""
    # what the client's planning read of the graph and of ``prior_map`` (their digests): the
    # worker keeps a file it has read while they are unchanged without asking the store again
    graph_stamp: str = ""
    prior_stamp: str = ""


def _stamp(p) -> str:
    if is_remote(p):
        return etag(p)
    st = p.stat()
    return f"{st.st_mtime_ns}:{st.st_size}"


@lru_cache(maxsize=8)
def _graph(path: str, stamp: str) -> LandmarkGraph:
    """A building's graph, read once per worker while the file stays as it was (a frozen
    record, shared by the walks: 26 ms a walk on the mall's 261 landmarks)."""
    return read_via_local(path, LandmarkGraph.load)


def load_params(path) -> Params:
    """A building's parameters (the defaults without a file), on disk or in a store."""
    return read_via_local(path, Params.load) if path else Params()


def unreadable(e: Exception, walk) -> bool:
    """Whether reading a walk's inputs failed because they could not be read — gone from the
    store or the disk, no permission, the network — rather than because of what they hold
    (issue #67 item 3: a bucket deleted mid-campaign left 43 walks failed for good)."""
    if isinstance(e, Unreadable) or isinstance(e, OSError):
        return True
    if isinstance(e, InputError):  # what a file says — unless the walk is no longer there
        return not is_remote(walk) and not Path(str(walk)).exists()
    return False


def run_walk(job: WalkJob) -> WalkResult:
    """Run the pipeline on one walk; never raises (a failure is a result with its error)."""
    t0 = time.perf_counter()
    res = WalkResult(job.key, job.building, job.walk.name, job.digest)
    reading = True
    try:
        s = read_via_local(job.walk, load_session)  # from the store by the worker itself
        g = _graph(str(job.graph), job.graph_stamp or _stamp(job.graph))
        p = load_params(job.params)
        reading = False
        s = s.in_frame(g.frame)
        has_truth = s.ground_truth is not None and len(s.ground_truth) > 1
        p, start = _given(job, s, g, p, has_truth)
        prior = None
        if job.prior_map is not None:
            ref = load_map(job.prior_map, without=job.key, stamp=job.prior_stamp)
            prior = prior_for_walk(ref, s, p.localize, "the building's other walks")
        within = job.after.region if job.after is not None and not start else None
        pipe = Pipeline(s, g, p, prior=prior, start_within=within)
        r = pipe.run()
        summ = r.summary(s, g)
        if pipe.start_within:
            summ = replace(summ, start_after=job.after)
        res = _what_it_gives(job, res, s, g, r, summ, p, start, has_truth)
        if job.out is not None:
            res = _put_maps(job, res)
    except Exception as e:  # noqa: BLE001 - recorded with the walk, the campaign goes on
        # nothing of a failed run is kept; its input, not the walk: tried again next run
        res = WalkResult(job.key, job.building, job.walk.name, job.digest, status="failed",
                         error=f"{type(e).__name__}: {e}", trace=traceback.format_exc(limit=3),
                         retry=reading and unreadable(e, job.walk))  # fmt: skip
    return replace(res, seconds=round(time.perf_counter() - t0, 3))


def _given(job: WalkJob, s, g: LandmarkGraph, p: Params, has_truth: bool):
    """The walk's parameters with the start and end it is given (the start None: inferred);
    a walk whose graph is another building's refused."""
    start = job.start if (job.start != "first-fix" or has_truth) else None
    start = resolve_start(start, s, g) if start else None  # None: inferred
    if start:
        p = p.updated(**{"pdr.start_node": start})
    if job.end:
        p = p.updated(**{"pdr.end_node": job.end})
    bad = mismatches(s, g)
    if bad:
        raise ValueError("walk and graph do not belong together: " + "; ".join(bad))
    return p, start


def _what_it_gives(job: WalkJob, res: WalkResult, s, g: LandmarkGraph, r, summ: Summary,
                   p: Params, start, has_truth: bool) -> WalkResult:  # fmt: skip
    """A walk run's result: its summary, what the passes after need, its maps as Parquet
    bytes."""
    inferred = None
    if not start:  # what the building's shared-start pass needs (campaign/shared_pass.py)
        fp = stand_fingerprint(s.wifi, r.track.start.time, p.localize.tau_dbm)
        inferred = InferredStart(
            tuple((str(n), float(m)) for n, m in r.track.start.candidates),
            None if fp is None else (tuple(fp[0].tolist()), tuple(fp[1].round(2).tolist())),
            p.localize.tau_dbm,
        )
    device = s.metadata.device  # merging aligns across models only
    # when it was recorded and where it ended: the next walk may start there (handover.py)
    clock = wall_clock(s)
    # with the scans held back for their σ on standby: the merge settles them (standby.py)
    walk_map = Fingerprints.from_radiomap(r.radiomap, g.frame, standby=True, device=device)
    maps: dict[str, bytes | None] = {"map": map_bytes(walk_map)}
    if job.prior_map is None:  # the first run's map: what the other walks' second runs read
        maps["first"] = None if summ.quarantined else map_bytes(walk_map.without_standby())
    maps["queries"] = map_bytes(Fingerprints.from_session(s)) if has_truth else None
    return replace(
        res.with_summary(summ), status="ok", start_inference=inferred, device=device,
        clock=None if clock is None else (clock[0], clock[1]),
        ended=where_ended(r.track) if r.track.steps.t.size else None,
        floor_name=s.metadata.floor_name, maps=maps,
    )  # fmt: skip


def _put_maps(job: WalkJob, res: WalkResult) -> WalkResult:
    """The walk's Parquet written to the store by the worker (absent ones removed) while its
    run holds the campaign's lock; the result keeps only that they are there (``stored``)."""
    if not still_holds(job.out, job.token):
        raise RuntimeError(f"the campaign run that sent this walk no longer holds {job.out}: "
                           "nothing written")  # fmt: skip
    put_maps(job.out / "walks" / job.key, res.maps)
    return replace(res, maps={}, stored=True)


def put_maps(d, maps: Mapping[str, bytes | None]) -> None:
    """A walk's Parquet files into its folder ``d``: each one given written, each None removed
    (a name absent — the first run's map after a run with the building's map — left as is)."""
    for name in MAP_FILES:
        if name not in maps:
            continue
        data = maps[name]
        if data is not None:
            put_bytes(d / f"{name}.parquet", data)
        else:
            remove(d / f"{name}.parquet")


def map_bytes(fp: Fingerprints, walks: np.ndarray | None = None) -> bytes:
    """A walk's map as :func:`load_map` reads it — Parquet: [``walk``,] x, y, floor,
    [standby,] one column per AP — made from its arrays in the worker (pandas' conversion took
    the campaign's client 65 ms a walk on the mall, one column per AP: the workers waited)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols: dict[str, Any] = {} if walks is None else {WALK_COLUMN: pa.array(walks.astype(str))}
    cols |= {"x": pa.array(fp.x), "y": pa.array(fp.y), "floor": pa.array(fp.floor)}
    if fp.standby is not None:
        cols["standby"] = pa.array(fp.on_standby)
    for name in ("t", "sigma"):  # what the building's joint estimate needs (walks/joint.py)
        if getattr(fp, name) is not None:
            cols[name] = pa.array(getattr(fp, name))
    for b, rss in zip(fp.bssids.tolist(), np.ascontiguousarray(fp.rss.T, dtype=float)):
        cols[str(b)] = pa.array(rss)
    # the frame and the phone model in its metadata, as a merged map's (map_read.py reads them:
    # `workstation merge` of two walks' map.parquet of one phone removed "offsets" between them)
    meta = {META_KEY.encode(): json.dumps({"format": 1, "device": fp.device,
            "frame": None if fp.frame is None else fp.frame.to_dict()}).encode()}  # fmt: skip
    table = pa.table(cols).replace_schema_metadata(meta)
    sink = pa.BufferOutputStream()  # (no dictionaries, no statistics: columns of a few values)
    pq.write_table(table, sink, use_dictionary=False, write_statistics=False)
    return sink.getvalue().to_pybytes()


def load_map(p, device: str = "", without: str | None = None, stamp: str = "") -> Fingerprints:
    """A walk's map as ``campaign._store`` wrote it (Parquet: x, y, floor, one column per AP),
    or the building's first-run maps in one (``without``: the rows of that walk left out;
    ``stamp``: their digest as :func:`first_maps` gave it, else the file is asked for one)."""
    if without is None:
        df = _frame(p)
    else:  # the building's first-run maps: read once per worker while unchanged
        df = _shared_frame(str(p), stamp or _stamp(p))
        df = df[df[WALK_COLUMN] != without].drop(columns=WALK_COLUMN)
    aps = [c for c in df.columns if c not in FIXED_COLUMNS]
    wait = df["standby"].to_numpy(bool) if "standby" in df.columns else None
    t, sigma = (df[c].to_numpy(float) if c in df.columns else None for c in ("t", "sigma"))
    return Fingerprints(
        df["x"].to_numpy(float), df["y"].to_numpy(float), df["floor"].to_numpy(float),
        np.array(aps, dtype=str), df[aps].to_numpy(float) if aps else np.empty((len(df), 0)),
        device=device, standby=wait if wait is not None and wait.any() else None, t=t, sigma=sigma,
    )  # fmt: skip


def _frame(p):
    import pandas as pd

    return pd.read_parquet(p if not is_remote(p) else io.BytesIO(_read_bytes(p)))


@lru_cache(maxsize=2)
def _shared_frame(path: str, stamp: str):
    """The building's first-run maps, one file every second-pass walk of it reads (1.4 MB a
    walk on the mall: from a store, 150 MB for its 106 walks when each read it)."""
    return _frame(place(path))


def code_digest() -> str:
    """The package's source, hashed: a new version of the code re-runs every walk."""
    h = hashlib.sha256(workstation.__version__.encode())
    root = Path(workstation.__file__).parent
    for f in sorted(root.rglob("*.py")):
        h.update(f.relative_to(root).as_posix().encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def _read_bytes(p) -> bytes:
    data = get_bytes(p)  # one request
    if data is None:
        raise InputError(p, "no such object, prefix or bucket")
    return data


def file_digest(path, tag: str | None = None) -> str:
    """A walk's or a building file's content, hashed; in a store its ETag and size (the client
    never reads a walk there: its workers do) — ``tag``: what a listing said of them
    (:func:`~workstation.io.store.listed`), else the object is asked."""
    h = hashlib.sha256()
    if path is None:
        return "-"
    if is_remote(path):
        return "etag:" + hashlib.sha256((tag or etag(path)).encode()).hexdigest()[:16]
    path = Path(path)
    try:
        # a session folder is flat: its own files (a campaign walk mistyped as "/" hashed the disk)
        files = sorted(p for p in path.iterdir() if p.is_file()) if path.is_dir() else [path]
    except OSError:  # unreadable (a path into /proc, a name too long): the run says why
        return "unreadable"
    for f in files:
        h.update(f.name.encode())
        try:
            with open(f, "rb") as fh:
                for chunk in iter(partial(fh.read, 1 << 20), b""):
                    h.update(chunk)
        except OSError:
            h.update(b"<unreadable>")
    return h.hexdigest()[:16]


def first_maps(path, firsts: Mapping[str, Path]) -> tuple[Path, str]:
    """The building's first-run maps in one Parquet file, a ``walk`` column saying whose each
    row is: each job of the second pass reads this one file and leaves its own rows out
    (:func:`load_map` with ``without``). Returns it and its content's digest."""
    keys = sorted(firsts)
    maps = [load_map(firsts[k]) for k in keys]
    walks = np.repeat(np.array(keys, dtype=str), [len(m) for m in maps])
    data = map_bytes(Fingerprints.merge(maps), walks)
    put_bytes(path, data)
    return path, "sha:" + hashlib.sha256(data).hexdigest()[:16]


def mark_done(state: dict[str, str], key: str, digest: str | None, res: WalkResult) -> None:
    """After a walk's files are stored, ``state`` (state.json) lists it under ``key`` with the
    ``digest`` of its inputs, so it is not run again until they change — unless its input
    could not be read (``retry``: tried again next time). ``digest`` None: it is forgotten."""
    if digest is None:
        state.pop(key, None)
    elif not res.retry:
        state[key] = digest
