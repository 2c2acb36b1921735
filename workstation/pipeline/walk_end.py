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

    ℓ(v) = −½ (r_v / σ)²,  σ = :func:`.sigma.open_sigma` (the open segment's own placement σ:
    the last anchor's spread and twice the drift of the distance walked from it),

and the best landmark v* closes the segment when it is plausible (ℓ(v*) ≥ ``LL_3SD``, within
3σ) and no landmark *elsewhere* — more than max(``ALTERNATIVE_START_M``, 2σ) from v*: another
place as the start inference counts places, and as the end's own σ can tell places apart (two
landmarks nearer than 2σ are one place to an end known to σ) — is nearly as likely
(ℓ(v*) − ℓ(v) ≥ ``AMBIGUOUS_LOGODDS``, the association's own threshold for a plausible
alternative). Landmarks of the same place that are nearly as likely make the end's spread,
which σ takes as it takes a match's
(``Track.end_spread``, :func:`.sigma.anchor_spread`). Then the open segment is bent to end on
v* (the backward correction, as every closed segment), and its scans are placed and trusted as
on a closed one. A walk that is ambiguous at the end keeps its open segment.

For a walk that matched nothing after its start, the dead-reckoned end is the one the
building's map turned and scaled (:mod:`.open_by_map`), where it did; σ stays that of the
distance the sensors walked.

The end is not a detection: it does not move the forward trajectory, only the corrected one
the radio map is placed on. It checks the walk as a match does only when it is placed as
tightly as a reference point may be (σ ≤ :data:`.verdict.END_CHECK_M`): then a walk that
matched no detection is not quarantined for it (:mod:`.verdict`).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .confidence import ALTERNATIVE_START_M, AMBIGUOUS_LOGODDS, LL_3SD, gaussian_ll
from .replay import bend
from .sigma import anchor_spread, open_sigma
from .tracker import Track

MIN_STEPS = 2  # an open segment shorter than this ended where it was last matched
PLACE_SIGMAS = 2.0  # landmarks nearer than this many σ of the end are one place to it

#: how the walk's end was taken (``Track.end_how``, summary.json's ``end_how``)
HOW = {
    "closed": "closed on the landmark it alone points at",
    "at_last_match": "where it was last matched",
    "ambiguous": "open: another place is nearly as likely",
    "far": "open: no landmark within 3σ of where it ends",
    "off": "open: pdr.end_on_landmark is off",
}


def describe_end(summary: dict) -> str:
    """Where a run's walk ends, in words, from its summary: "L140 (closed on …)"."""
    return f"{summary.get('end_node') or '—'} ({HOW.get(str(summary.get('end_how')), '')})"


def end_on_landmark(track: Track, pos: dict[str, tuple[float, float, float]]) -> Track:
    """``track`` with its open last segment closed on the landmark the walk unambiguously ends
    at (``Track.end_node``), or left open; ``Track.end_how`` says which (:data:`HOW`).
    ``pos``: landmark → (x, y, floor)."""
    last = track.seg_from.size - 1
    if last < 0 or track.seg_to[last] != "":
        return replace(track, end_how="at_last_match")
    mine = np.flatnonzero(track.segment == last)
    if mine.size < MIN_STEPS:
        return replace(track, end_how="at_last_match")
    i0 = mine[0]
    ax, ay, _ = pos.get(str(track.seg_from[last]), (track.x[i0], track.y[i0], 0.0))
    fx, fy = track.x[mine], track.y[mine]  # σ from the distance the sensors walked
    walked = float(np.hypot(np.diff(fx, prepend=ax), np.diff(fy, prepend=ay)).sum())
    px, py = track.x_bc[mine], track.y_bc[mine]  # the forward stretch, or as the map turned it
    s0 = anchor_spread(track)[0][last]
    sd = open_sigma(s0, walked)
    ex, ey, ef = float(px[-1]), float(py[-1]), float(track.floor[mine[-1]])
    ids = [v for v, (_, _, f) in pos.items() if f == ef]
    if not ids:
        return replace(track, end_how="far", end_sigma=round(sd, 2))
    xy = np.array([pos[v][:2] for v in ids])
    ll = gaussian_ll(np.hypot(xy[:, 0] - ex, xy[:, 1] - ey), sd)
    j = int(np.argmax(ll))
    v = ids[j]
    vx, vy, _ = pos[v]
    apart = np.hypot(xy[:, 0] - vx, xy[:, 1] - vy)
    elsewhere = apart > max(ALTERNATIVE_START_M, PLACE_SIGMAS * sd)
    margin = float(ll[j] - ll[elsewhere].max()) if elsewhere.any() else math.inf
    if ll[j] < LL_3SD or margin < AMBIGUOUS_LOGODDS:
        how = "far" if ll[j] < LL_3SD else "ambiguous"
        return replace(track, end_how=how, end_margin=round(margin, 2), end_sigma=round(sd, 2))
    spread = float(apart[ll >= ll[j] - AMBIGUOUS_LOGODDS].max())
    xb, yb = track.x_bc.copy(), track.y_bc.copy()
    xb[mine], yb[mine] = bend(px, py, ax, ay, ex, ey, vx, vy)
    seg_to = np.array([*track.seg_to[:last].tolist(), v], dtype=str)
    return replace(
        track, x_bc=xb, y_bc=yb, seg_to=seg_to, end_node=v, end_how="closed",
        end_margin=round(margin, 2), end_spread=round(spread, 2), end_sigma=round(sd, 2),
    )  # fmt: skip
