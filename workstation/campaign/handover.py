"""The campaign's pass for walks recorded one after another (:mod:`workstation.walks.chain`):
each walk whose inferred start is ambiguous, recorded right after a walk whose start is certain
(given by the surveyor, or inferred beyond doubt), runs again with its start searched within
walking reach of where that walk ended. In rounds, in time order: a walk made certain hands on
to the next one in the following round. A walk handed a start before and no longer (the walk
before changed, or was fixed elsewhere) runs again on its own."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from workstation.campaign.jobs import mark_done
from workstation.campaign.walk_result import WalkResult
from workstation.graph import LandmarkGraph
from workstation.io.store import read_via_local
from workstation.walks.chain import DOUBTFUL_END, follows, handover, region_arg, same_floor_named


def _ambiguous(meta: WalkResult) -> bool:
    return meta.ok and "start_ambiguous" in meta.summary.reasons


def _certain(meta: WalkResult) -> bool:
    """Its start and end are not in doubt (where it ended: ``ended``, when it has steps)."""
    return meta.ok and not (set(meta.summary.reasons) & DOUBTFUL_END)


def handed_starts(out: Path, specs, jobs, state: dict[str, str], force: bool, say, execute,
                  meta_of: Callable[..., WalkResult], store: Callable,
                  commit: Callable = lambda now=False: None) -> list:  # fmt: skip
    """Run the pass (module doc) over every building; returns the jobs run (``commit``:
    writes the state after each, as the campaign's other passes do)."""
    ran: list = []
    for b in specs:
        bj = [j for j in jobs if j.building == b.name]
        metas = {j.key: meta_of(out, j) for j in bj}
        links = follows([metas[j.key].clock for j in bj], [metas[j.key].device for j in bj])
        if not links:
            continue
        graph = read_via_local(b.graph, LandmarkGraph.load)
        order = sorted(links, key=lambda i: _began(metas[bj[i].key]))
        decided: set[int] = set()  # walks whose start this pass has settled
        for _ in range(len(order)):  # rounds: a walk made certain hands on in the next
            runs: dict[str, tuple] = {}
            for i in order:
                a, gap = links[i]
                final_a = a not in links or (a in decided and bj[a].key not in runs)
                if i in decided or not final_a:
                    continue  # done, or wait for the walk before to settle
                decided.add(i)
                run = _handed(bj[i], metas[bj[i].key], bj[a].key, metas[bj[a].key], gap, graph,
                              state, force)  # fmt: skip
                if run is not None:
                    runs[bj[i].key] = run
            if not runs:
                break
            for job in _run_round(runs, execute, state, say, lambda r: store(out, r), commit):
                metas[job.key] = meta_of(out, job)
            ran += [r[0] for r in runs.values()]
    return ran


def _began(meta: WalkResult) -> float:
    return meta.clock[0] if meta.clock is not None else 0.0


def _handed(j, meta: WalkResult, before_key: str, before: WalkResult, gap: float,
            graph: LandmarkGraph, state: dict[str, str], force: bool) -> tuple | None:  # fmt: skip
    """Whether walk ``j`` runs again in this round: (its job, the handover, its summary) — the
    handover None when it runs on its own again — or None."""
    handed = meta.start_after
    if not (meta.start_inference and (handed or _ambiguous(meta))):
        return None  # its start was given, or inferred beyond doubt on its own
    if not _certain(before) or before.ended is None:
        return (j, None, meta) if handed else None  # handed a start before, no longer
    floors = same_floor_named(before.floor_name, meta.floor_name)
    h = handover(before.ended, gap, graph, before_key.split("/", 1)[1], floors)
    if not h.among:
        return None
    job = replace(j, after=h.handed(),
                  digest=f"{j.digest}|after:{before_key}:{region_arg(h.region)}")  # fmt: skip
    if force or not handed or state.get(j.key + "@after") != job.digest:
        return job, h, meta
    return None


def _run_round(runs: dict[str, tuple], execute, state: dict[str, str], say, store: Callable,
               commit: Callable):  # fmt: skip
    """A round's walks run, each stored with the walk's own start inference kept, then its
    state committed; yields each job stored."""
    for res in execute([r[0] for r in runs.values()]):
        job, h, meta = runs.get(res.key, (None, None, None))
        if job is None:
            continue
        res = replace(res, start_inference=meta.start_inference)  # the walk's own, kept
        if h is not None:
            res = replace(res, start_after=h.handed())
            say(f"  {job.key}: start searched within {h.radius_m:.0f} m of where "
                f"{h.before} ended ({h.gap_s:.0f} s before): {_said(res)}")  # fmt: skip
        store(res)  # (then the state: it lists only what is stored)
        mark_done(state, job.key + "@after", None if h is None else job.digest, res)
        commit()
        yield job


def _said(res: WalkResult) -> str:
    if not res.ok:
        return "failed"
    s = res.summary
    return s.start_node + (", still ambiguous" if "start_ambiguous" in s.reasons else "")
