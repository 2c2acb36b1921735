"""A walk that matched nothing after its start, turned and stretched onto the building's radio
map (beyond the paper; docs/decisions.md, "A walk that matched nothing follows the map").

Until a landmark is matched, dead reckoning runs on the initial step length and the compass's
alignment of the gyro at the start: on mall F1 such walks run 8 % short along the way and
10–30° off across it, and nothing corrects them — their end closes (:mod:`.walk_end`) where that
drifting track ends, often on the wrong landmark. A radio map of the building's *other* walks
(:mod:`.map_prior`) puts each of the walk's scans somewhere (1-NN); turning the track about its
start by φ and scaling it by s so that its scans land where the map puts them fixes both
errors, with the map's outliers weighed as the chains' are:

    (φ, s) = argmax  β · Σ log(w N₂(d_i(φ, s); σ) + (1 − w)/A)  −  ½ (φ/σ_φ)²  −  ½ (ln s/σ_s)²

(:func:`.map_prior.scan_terms`, β = ``pdr.map_weight``), on a grid of ``TURNS`` × ``SCALES``.
The priors are what the sensors leave open: σ_φ = ``TURN_SD`` (the start's compass alignment
is 13° off over the first steps, median, mall F1), σ_s = ``SCALE_SD`` (an uncalibrated step
length is a tenth off). As in choosing a chain, the map decides only when it is decisive (the
fit beats the sensors' track by ``AMBIGUOUS_LOGODDS``), and never against an end that checks
the walk: where the sensors' track closed its end on a landmark with σ at most
:data:`.state.END_CHECK_M`, that stays (on one mall split a walk so checked, 1.6 m off at its
taps, was shrunk by the map to 6 m off and lost its check). Otherwise the end is closed again
on the turned track, with its σ unchanged (the quarantine's check stays the sensors').

Only a walk's stretch from its start: after a matched landmark the tracker has turned the gyro
onto the edge walked and learnt the step length (eq. 10), and turning the stretch after it by
the map did more harm than good on the mall (a map off by 10–30 m where few walks passed turned
a well-tracked stretch by 22–37°). Only the corrected trajectory moves; the forward one stays
the sensors'.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from workstation.params import PDRParams
from workstation.pipeline.confidence import AMBIGUOUS_LOGODDS
from workstation.pipeline.tracking.map_prior import MapPrior, scan_terms
from workstation.pipeline.tracking.state import OpenFit, Track

TURN_SD = np.radians(15.0)
SCALE_SD = 0.1
TURNS = np.radians(np.arange(-45.0, 45.1, 1.5))
SCALES = np.exp(np.linspace(-0.25, 0.25, 21))
MIN_SCANS = 3  # fewer scans say nothing the prior would not


def fit_open(
    track: Track, prior: MapPrior, p: PDRParams, pos: dict[str, tuple[float, float, float]]
) -> Track:
    """``track`` turned and scaled about its start so that its scans land where the map puts
    them, when nothing was matched after the start and its end is not yet closed (module
    doc); ``Track.open_fit`` says how."""
    if track.segments.from_node.size != 1 or track.segments.to_node[0] != "" or p.map_weight <= 0:
        return track  # a landmark was matched after the start: the sensors were recalibrated
    mine = np.flatnonzero(track.steps.segment == 0)
    start = pos.get(track.start.node)
    if mine.size < 2 or start is None:  # (no step at all: nothing to turn)
        return track
    sel = (prior.t > track.start.time) & (prior.t <= track.steps.t[-1])
    if sel.sum() < MIN_SCANS:
        return track
    ax, ay = start[0], start[1]
    x, y, f = track.position_at(prior.t[sel], corrected=True)
    c, s = np.cos(TURNS)[:, None, None], np.sin(TURNS)[:, None, None]
    k = SCALES[None, :, None]
    qx, qy = x - ax, y - ay
    gx, gy = ax + k * (c * qx - s * qy), ay + k * (s * qx + c * qy)
    ll = p.map_weight * scan_terms(gx, gy, f, prior, sel, p).sum(axis=-1)
    ll -= 0.5 * (TURNS[:, None] / TURN_SD) ** 2 + 0.5 * (np.log(SCALES)[None, :] / SCALE_SD) ** 2
    i, j = np.unravel_index(int(np.argmax(ll)), ll.shape)
    if ll[i, j] - ll[TURNS.size // 2, SCALES.size // 2] < AMBIGUOUS_LOGODDS:
        # the map is not decisive: the sensors' track stays
        return replace(track, open_fit=OpenFit(0.0, 1.0, int(sel.sum())))
    phi, sc = float(TURNS[i]), float(SCALES[j])
    xb, yb = track.steps.x_bc.copy(), track.steps.y_bc.copy()
    cx, cy = xb[mine] - ax, yb[mine] - ay
    xb[mine] = ax + sc * (np.cos(phi) * cx - np.sin(phi) * cy)
    yb[mine] = ay + sc * (np.sin(phi) * cx + np.cos(phi) * cy)
    fit = OpenFit(round(float(np.degrees(phi)), 1), round(sc, 3), int(sel.sum()))
    return replace(track, steps=replace(track.steps, x_bc=xb, y_bc=yb), open_fit=fit)
