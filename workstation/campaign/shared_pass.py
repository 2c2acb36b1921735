"""The campaign's pass for walks that stood at one place: per building, the walks whose starts
were inferred are grouped by their stand fingerprints (:mod:`workstation.walks.shared_start`);
a walk whose own best start differs from its group's is run again from the group's start (its
first run's start inference is kept with it, so the grouping is the same next time), a walk a
group no longer moves is run again on its own, and a quarantined walk whose group chose its
own best start is no longer ambiguous."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from workstation.campaign.jobs import WalkJob, mark_done, stored, walk_summary
from workstation.campaign.records import Records
from workstation.walks.shared_start import decide_shared


@dataclass(frozen=True)
class _Inferred:
    """A building's walks whose start was inferred: their place among its jobs, what their
    first runs said (candidates, stand fingerprint) and the group each one's stand joined."""

    idx: list[int]  # positions in the building's jobs
    infos: list[dict]
    cands: list[tuple[tuple[str, float], ...]]  # best first
    wanted: dict[int, dict]  # by position in ``idx``: the group's start, its other walks


def _inferred(bj: list[WalkJob], metas: list[dict]) -> _Inferred | None:
    idx = [i for i, m in enumerate(metas) if m.get("status") == "ok" and m.get("start_inference")]
    if not idx:
        return None
    infos = [metas[i]["start_inference"] for i in idx]
    prints = [None if f["stand"] is None else (np.array(f["stand"][0], dtype=str),
              np.array(f["stand"][1], float)) for f in infos]  # fmt: skip
    cands = [tuple((str(n), float(m)) for n, m in f["candidates"]) for f in infos]
    wanted: dict[int, dict] = {}
    for g in decide_shared(prints, cands, float(infos[0]["tau_dbm"])):
        for k in g.walks:
            wanted[k] = {"start": g.start, "with": [bj[idx[o]].key for o in g.walks if o != k],
                         "totals": g.totals}  # fmt: skip
    return _Inferred(idx, infos, cands, wanted)


def confirmed(meta: dict, want: dict) -> dict:
    """Walks that stood together chose this walk's own best start: it is no longer ambiguous
    (its other quarantine reasons stay)."""
    s = walk_summary(meta)
    s = s.updated(quarantine=tuple(q for q in s.quarantine if q.reason != "start_ambiguous"))
    return {**meta, "summary": stored(s), "start_shared": {**want, "kept": True}}


def _decide(bj, metas, state: dict, force: bool, say, records: Records) -> dict[str, tuple]:
    """One building's runs: key → (job, its first inference, the group) — (job, None, None) for
    a walk that runs on its own again."""
    found = _inferred(bj, metas)
    runs: dict[str, tuple] = {}
    if found is None:
        return runs
    for k, i in enumerate(found.idx):
        j, meta, want, cands = bj[i], metas[i], found.wanted.get(k), found.cands[k]
        if want and cands and want["start"] != cands[0][0]:
            job = replace(j, start=want["start"], digest=f"{j.digest}|shared:{want['start']}")
            if force or not meta.get("start_shared") or state.get(j.key + "@shared") != job.digest:
                runs[j.key] = (job, found.infos[k], want)
                say(f"  {j.key}: start {cands[0][0]} → {want['start']}, decided with "
                    + ", ".join(want["with"]))  # fmt: skip
        elif meta.get("start_shared") and not (want and meta["start_shared"].get("kept")):
            runs[j.key] = (j, None, None)  # moved before, not now: its own run again
        elif want and walk_summary(meta).quarantined:
            records.write(j.key, confirmed(meta, want))  # the group chose its own start
    return runs


def shared_starts(specs, jobs, state: dict, force: bool, say, execute, records: Records,
                  store: Callable[[dict], None],
                  commit: Callable = lambda now=False: None) -> list:  # fmt: skip
    """The pass over every building (module doc); ``store(res)`` keeps a run's result.
    Returns the jobs run."""
    runs: dict[str, tuple] = {}
    for b in specs:
        bj = [j for j in jobs if j.building == b.name]
        runs |= _decide(bj, [records.get(j.key) for j in bj], state, force, say, records)
    for res in execute([r[0] for r in runs.values()]):
        job, info, want = runs.get(res["key"], (None, None, None))
        if job is None:
            continue
        if want is not None:
            res["start_inference"], res["start_shared"] = info, want
        store(res)  # (then the state: it lists only what is stored)
        mark_done(state, job.key + "@shared", None if want is None else job.digest, res)
        commit()
    return [r[0] for r in runs.values()]
