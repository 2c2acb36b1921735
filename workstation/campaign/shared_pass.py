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

from workstation.campaign.jobs import WalkJob, mark_done
from workstation.campaign.records import Records
from workstation.campaign.walk_result import GroupStart, InferredStart, WalkResult
from workstation.walks.shared_start import decide_shared


@dataclass(frozen=True)
class _Inferred:
    """A building's walks whose start was inferred: their place among its jobs, what their
    first runs said (candidates, stand fingerprint) and the group each one's stand joined."""

    idx: list[int]  # positions in the building's jobs
    infos: list[InferredStart]
    wanted: dict[int, GroupStart]  # by position in ``idx``: the group's start, its other walks


def _inferred(bj: list[WalkJob], metas: list[WalkResult]) -> _Inferred | None:
    idx = [i for i, m in enumerate(metas) if m.ok and m.start_inference]
    if not idx:
        return None
    infos = [i for i in (metas[k].start_inference for k in idx) if i is not None]
    prints = [None if f.stand is None else (np.array(f.stand[0], dtype=str),
              np.array(f.stand[1], float)) for f in infos]  # fmt: skip
    cands = [f.candidates for f in infos]
    wanted: dict[int, GroupStart] = {}
    for g in decide_shared(prints, cands, float(infos[0].tau_dbm)):
        for k in g.walks:
            wanted[k] = GroupStart(g.start, tuple(bj[idx[o]].key for o in g.walks if o != k),
                                    g.totals)  # fmt: skip
    return _Inferred(idx, infos, wanted)


def confirmed(meta: WalkResult, want: GroupStart) -> WalkResult:
    """Walks that stood together chose this walk's own best start: it is no longer ambiguous
    (its other quarantine reasons stay)."""
    s = meta.summary
    s = replace(s, quarantine=tuple(q for q in s.quarantine if q.reason != "start_ambiguous"))
    return replace(meta.with_summary(s), start_shared=replace(want, kept=True))


def _decide(bj, metas: list[WalkResult], state: dict[str, str], force: bool, say,
            records: Records) -> dict[str, tuple]:  # fmt: skip
    """One building's runs: key → (job, its first inference, the group) — (job, None, None) for
    a walk that runs on its own again."""
    found = _inferred(bj, metas)
    runs: dict[str, tuple] = {}
    if found is None:
        return runs
    for k, i in enumerate(found.idx):
        j, meta, want, cands = bj[i], metas[i], found.wanted.get(k), found.infos[k].candidates
        if want and cands and want.start != cands[0][0]:
            job = replace(j, start=want.start, digest=f"{j.digest}|shared:{want.start}")
            if force or not meta.start_shared or state.get(j.key + "@shared") != job.digest:
                runs[j.key] = (job, found.infos[k], want)
                say(f"  {j.key}: start {cands[0][0]} → {want.start}, decided with "
                    + ", ".join(want.walks))  # fmt: skip
        elif meta.start_shared and not (want and meta.start_shared.kept):
            runs[j.key] = (j, None, None)  # moved before, not now: its own run again
        elif want and meta.summary.quarantined:
            records.write(confirmed(meta, want))  # the group chose its own start
    return runs


def shared_starts(specs, jobs, state: dict[str, str], force: bool, say, execute,
                  records: Records, store: Callable[[WalkResult], None],
                  commit: Callable = lambda now=False: None) -> list:  # fmt: skip
    """The pass over every building (module doc); ``store(res)`` keeps a run's result.
    Returns the jobs run."""
    runs: dict[str, tuple] = {}
    for b in specs:
        bj = [j for j in jobs if j.building == b.name]
        runs |= _decide(bj, [records.get(j.key) for j in bj], state, force, say, records)
    for res in execute([r[0] for r in runs.values()]):
        job, info, want = runs.get(res.key, (None, None, None))
        if job is None:
            continue
        if want is not None:
            res = replace(res, start_inference=info, start_shared=want)
        store(res)  # (then the state: it lists only what is stored)
        mark_done(state, job.key + "@shared", None if want is None else job.digest, res)
        commit()
    return [r[0] for r in runs.values()]
