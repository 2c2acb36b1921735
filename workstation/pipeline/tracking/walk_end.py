"""The walk ends on a landmark (beyond the paper; issue #28, ``pdr.end_on_landmark``).

A survey walk is recorded from landmark to landmark: it starts on one (given, or inferred) and
the surveyor stops recording on one. The paper uses the start and leaves the end alone, so what
was walked after the last matched landmark — the *open* last segment — is dead reckoning that
nothing corrects and the radio map distrusts. On the Microsoft mall the recording stops a
median 1.1 s after the last tap (95 % within 3.3 s), where the walker did not turn or stop, so
no detector can see that landmark; 18 % of the scans are on the open segment, placed 5.9 m off
(mean) against 1.7 m on closed ones.

So the end of the walk is matched like a detection whose rule every landmark carries — by
where the walk puts it alone, as a relocalization is: the candidates are the landmarks on the
end's floor, each scored by the Gaussian log-likelihood of its distance r from the dead-reckoned
end,

    ℓ(v) = −½ (r_v / σ)²,  σ = :func:`.confidence.open_sigma` (the open segment's own placement σ:
    the last anchor's spread and twice the drift of the distance walked from it),

and the best landmark v* closes the segment when it is plausible (ℓ(v*) ≥ ``LL_3SD``, within
3σ) and no landmark *elsewhere* — more than max(``ALTERNATIVE_START_M``, 2σ) from v*: another
place as the start inference counts places, and as the end's own σ can tell places apart (two
landmarks nearer than 2σ are one place to an end known to σ) — is nearly as likely
(ℓ(v*) − ℓ(v) ≥ ``AMBIGUOUS_LOGODDS``, the association's own threshold for a plausible
alternative). Landmarks of the same place that are nearly as likely make the end's spread,
which σ takes as it takes a match's
(``Track.end.spread``, :func:`.state.anchor_spread`). Then the open segment is bent to end on
v* (the backward correction, as every closed segment), and its scans are placed and trusted as
on a closed one. A walk that is ambiguous at the end keeps its open segment.

For a walk that matched nothing after its start, the dead-reckoned end is the one the
building's map turned and scaled (:mod:`.open_by_map`), where it did; σ stays that of the
distance the sensors walked.

The surveyor may also *give* the end (``pdr.end_node``: "End here", ``--end``), who knows
where the recording stopped as they know where it started: the open stretch is bent onto it,
and when the sensors end the walk at that place (within 3σ, never less than 5 m) it checks the
walk as a match does; a walk the sensors end elsewhere is left as they had it and quarantined
for it (:func:`_given_end`, :mod:`.verdict`).

The end is not a detection: it does not move the forward trajectory, only the corrected one
the radio map is placed on. It checks the walk as a match does only when it is placed as
tightly as a reference point may be (σ ≤ :data:`.state.END_CHECK_M`): then a walk that
matched no detection is not quarantined for it (:mod:`.verdict`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, NamedTuple

import numpy as np

from workstation.pipeline.confidence import (
    ALTERNATIVE_START_M,
    AMBIGUOUS_LOGODDS,
    LL_3SD,
    gaussian_ll,
    open_sigma,
)
from workstation.pipeline.tracking.replay import bend
from workstation.pipeline.tracking.state import EndHow, Track, anchor_spread

MIN_STEPS = 2  # an open segment shorter than this ended where it was last matched
PLACE_SIGMAS = 2.0  # landmarks nearer than this many σ of the end are one place to it

#: how the walk's end was taken (``Track.end.how``, summary.json's ``end_how``)
HOW: dict[EndHow, str] = {
    "closed": "closed on the landmark it alone points at",
    "at_last_match": "where it was last matched",
    "ambiguous": "open: another place is nearly as likely",
    "far": "open: no landmark within 3σ of where it ends",
    "off": "open: pdr.end_on_landmark is off",
    "given": "given by the surveyor; the sensors end the walk at that place",
    "given_far": "given by the surveyor, but the sensors end the walk elsewhere",
}


def end_on_landmark(
    track: Track, pos: dict[str, tuple[float, float, float]], given: str | None = None
) -> Track:
    """``track`` with its open last segment closed on the landmark the walk unambiguously ends
    at (``Track.end.node``), or left open; ``Track.end.how`` says which (:data:`HOW`).
    ``pos``: landmark → (x, y, floor). ``given``: the landmark the surveyor says the walk
    ended on (``pdr.end_node``; :func:`_given_end`)."""
    last = track.segments.from_node.size - 1
    mine = np.flatnonzero(track.steps.segment == last) if last >= 0 else np.zeros(0, int)
    if given:
        return _given_end(track, pos, given, mine)
    if last < 0 or track.segments.to_node[last] != "":
        return _ended(track, how="at_last_match")
    if mine.size < MIN_STEPS:
        return _ended(track, how="at_last_match")
    o = _open_stretch(track, pos, last, mine)
    ax, ay, px, py, sd = o.ax, o.ay, o.px, o.py, o.sd
    ex, ey, ef = o.ex, o.ey, o.ef
    ids = [v for v, (_, _, f) in pos.items() if f == ef]
    if not ids:
        return _ended(track, how="far", sigma=round(sd, 2))
    xy = np.array([pos[v][:2] for v in ids])
    ll = gaussian_ll(np.hypot(xy[:, 0] - ex, xy[:, 1] - ey), sd)
    j = int(np.argmax(ll))
    v = ids[j]
    vx, vy, _ = pos[v]
    apart = np.hypot(xy[:, 0] - vx, xy[:, 1] - vy)
    elsewhere = apart > max(ALTERNATIVE_START_M, PLACE_SIGMAS * sd)
    margin = float(ll[j] - ll[elsewhere].max()) if elsewhere.any() else math.inf
    if ll[j] < LL_3SD or margin < AMBIGUOUS_LOGODDS:
        how: EndHow = "far" if ll[j] < LL_3SD else "ambiguous"
        return _ended(track, how=how, margin=round(margin, 2), sigma=round(sd, 2))
    spread = float(apart[ll >= ll[j] - AMBIGUOUS_LOGODDS].max())
    xb, yb = track.steps.x_bc.copy(), track.steps.y_bc.copy()
    xb[mine], yb[mine] = bend(px, py, ax, ay, ex, ey, vx, vy)
    seg_to = np.array([*track.segments.to_node[:last].tolist(), v], dtype=str)
    return _ended(
        track, (xb, yb, seg_to), node=v, how="closed", margin=round(margin, 2),
        spread=round(spread, 2), sigma=round(sd, 2),
    )  # fmt: skip


def _ended(
    track: Track, bent: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    **end: Any,
) -> Track:  # fmt: skip
    """``track`` with its end changed as ``end`` says (:class:`.End`'s fields) and, when
    ``bent``, its corrected x, y and the segments' last landmarks replaced by those."""
    track = replace(track, end=replace(track.end, **end))
    if bent is None:
        return track
    xb, yb, seg_to = bent
    return replace(track, steps=replace(track.steps, x_bc=xb, y_bc=yb),
                   segments=replace(track.segments, to_node=seg_to))  # fmt: skip


def _agree_m(sd: float) -> float:
    """How far the sensors' end may lie from a given end and still be that place: 3σ, and
    never less than ``ALTERNATIVE_START_M`` — landmarks nearer than that are one place to the
    start inference, and a walker taps or stops a few metres from where the last turn was."""
    return max(3.0 * sd, ALTERNATIVE_START_M)


def _given_end(track: Track, pos: dict, given: str, mine: np.ndarray) -> Track:
    """The walk ends on ``given``, as the surveyor says (who stopped recording there): the open
    last segment is bent to end on it as on a matched landmark. Whether the sensors agree is
    recorded: ``given`` when the dead-reckoned end is that place (:func:`_agree_m`, σ as for
    any end, :func:`.confidence.open_sigma`) on its floor, ``given_far`` otherwise — then the walk,
    its start or the given end is wrong: nothing is bent (the track stays the sensors'), the
    disagreement is kept as the end's spread, and the quarantine says so (:mod:`.verdict`). A
    walk that ended at its last match (no open stretch) is compared by that landmark."""
    if given not in pos:
        raise ValueError(f"the given end {given!r} is not a landmark of the graph")
    vx, vy, vf = pos[given]
    last = track.segments.from_node.size - 1
    if last < 0 or track.segments.to_node[last] != "" or mine.size < MIN_STEPS:
        # the walk ended where it was last matched: compare that landmark with the given one
        spread0, spread1 = anchor_spread(track)
        if last < 0:
            node, spread = track.start.node, 0.0
        elif track.segments.to_node[last]:
            node, spread = str(track.segments.to_node[last]), float(spread1[last])
        else:
            node, spread = str(track.segments.from_node[last]), float(spread0[last])
        nx, ny, nf = pos.get(node, (vx, vy, vf))
        sd = open_sigma(spread, 0.0)
        ok = nf == vf and math.hypot(nx - vx, ny - vy) <= _agree_m(sd)
        return _ended(track, node=given, how="given" if ok else "given_far", sigma=round(sd, 2))
    o = _open_stretch(track, pos, last, mine)
    off = math.hypot(vx - o.ex, vy - o.ey) if o.ef == vf else math.inf
    if off > _agree_m(o.sd):  # the sensors' track is kept as it was, and the walk held for it
        return _ended(
            track, node=given, how="given_far", sigma=round(o.sd, 2), spread=round(off, 2)
        )
    xb, yb = track.steps.x_bc.copy(), track.steps.y_bc.copy()
    xb[mine], yb[mine] = bend(o.px, o.py, o.ax, o.ay, o.ex, o.ey, vx, vy)
    seg_to = np.array([*track.segments.to_node[:last].tolist(), given], dtype=str)
    return _ended(
        track, (xb, yb, seg_to), node=given, how="given", sigma=round(o.sd, 2), spread=0.0
    )


class _Stretch(NamedTuple):
    """The open last segment: its anchor, its steps as placed, σ of its end, and the end."""

    ax: float
    ay: float
    px: np.ndarray
    py: np.ndarray
    sd: float
    ex: float
    ey: float
    ef: float


def _open_stretch(track: Track, pos: dict, last: int, mine: np.ndarray) -> _Stretch:
    """The open last segment's steps ``mine`` from its anchor: σ of its end from the distance
    the sensors walked, the steps as placed (the forward stretch, or as the map turned it)."""
    i0 = mine[0]
    ax, ay, _ = pos.get(
        str(track.segments.from_node[last]), (track.steps.x[i0], track.steps.y[i0], 0.0)
    )
    fx, fy = track.steps.x[mine], track.steps.y[mine]
    walked = float(np.hypot(np.diff(fx, prepend=ax), np.diff(fy, prepend=ay)).sum())
    px, py = track.steps.x_bc[mine], track.steps.y_bc[mine]
    sd = open_sigma(anchor_spread(track)[0][last], walked)
    return _Stretch(
        ax, ay, px, py, sd, float(px[-1]), float(py[-1]), float(track.steps.floor[mine[-1]])
    )
