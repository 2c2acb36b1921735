"""Landmark detection (§III-A): candidate times where sensor data show a landmark pattern.

- ``acc`` (eq. 2): walking ≥ K1, still for K2 ∈ [K2min, K2max], walking ≥ K1 again. The
  candidate is at the start of the stop (the walker reaches the door).
- ``gyro`` (eq. 3): the vertical rate, averaged over a 10-sample window, exceeds ε_gyro. One
  candidate per turn (the stretch until the rate falls below a third of ε_gyro), at its
  strongest sample, with the turn angle.
- ``baro_entry`` / ``baro_exit`` (eq. 4–6): window means p_i of the pressure; an entry is a
  level window (|p_i − p_{i−1}| < ε_baro1) followed by a monotonic run of K windows, K grown
  while the sign holds, whose total change exceeds ε_baro2; the exit is the mirror image.
  Beyond the paper (docs/decisions.md): a dead band, landings up to ``max_level_s``, and a run
  too small alone joined with the next one of its sign as one more candidate change.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from workstation.errors import WorkstationError
from workstation.params import AccLandmarkParams, BaroLandmarkParams, GyroLandmarkParams, Params
from workstation.pipeline.filters import moving_mean, samples_at
from workstation.pipeline.heading import Heading
from workstation.pipeline.steps import Steps
from workstation.rules import FLOOR_ENTRY, FLOOR_EXIT, NAMES, STOP, TABLE, TURN
from workstation.session import Scalar
from workstation.session.model import median_rate

KINDS = NAMES  # one kind of detection per landmark rule (workstation/rules.py)


@dataclass(frozen=True)
class Detections:
    """Landmark candidates in time order. ``value``: stop duration (s) for acc, turn angle
    (rad, + = left) for gyro, pressure change (hPa, − = going up) for barometer ones."""

    t: np.ndarray
    kind: np.ndarray  # str
    t_end: np.ndarray
    value: np.ndarray
    t_start: np.ndarray  # where the pattern began (a floor change's entry, for an exit)

    def __len__(self) -> int:
        return int(self.t.size)

    def count(self, kind: str) -> int:
        return int(np.count_nonzero(self.kind == kind))


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start and end (exclusive) indices of True runs."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return np.flatnonzero(d == 1), np.flatnonzero(d == -1)


Row = tuple  # (t, kind, t_end, value, t_start)


def detect_acc(steps: Steps, p: AccLandmarkParams) -> list[Row]:
    t, walking = steps.state_t, steps.walking
    if t.size < 2:
        return []
    ws, we = _runs(walking)
    out: list[tuple] = []  # (t, kind, t_end, value, t_start)
    for i in range(len(ws) - 1):
        t_walk_before = t[we[i] - 1] - t[ws[i]]
        t_still = t[ws[i + 1]] - t[we[i] - 1]
        t_walk_after = t[we[i + 1] - 1] - t[ws[i + 1]]
        if (
            t_walk_before >= p.walking_s
            and t_walk_after >= p.walking_s
            and p.still_min_s <= t_still <= p.still_max_s
        ):
            out.append((t[we[i] - 1], STOP, t[ws[i + 1]], t_still, t[we[i] - 1]))
    return out


def detect_gyro(heading: Heading, p: GyroLandmarkParams) -> list[Row]:
    t = heading.t
    window = samples_at(p.window, median_rate(t))
    if t.size < window:
        return []
    rate = moving_mean(heading.vertical_rate, window)
    s, e = _runs(np.abs(rate) > p.threshold_rad_s)
    if not s.size and p.slow_turn_deg <= 0:
        return []
    # merge turns that are closer than merge_s
    keep_s, keep_e = list(s[:1]), list(e[:1])
    for a, b in zip(s[1:], e[1:]):
        if t[a] - t[keep_e[-1] - 1] < p.merge_s and np.sign(rate[a]) == np.sign(rate[keep_s[-1]]):
            keep_e[-1] = b
        else:
            keep_s.append(a)
            keep_e.append(b)
    out: list[tuple] = []  # (t, kind, t_end, value, t_start)
    # the turn: extend to where the rate falls below a third of the threshold; runs that extend
    # to the same turn (the rate never fell that low between them) are one turn, at its
    # strongest sample
    weak = np.flatnonzero(np.abs(rate) < p.threshold_rad_s / 3)

    def stretch(a: int, b: int) -> tuple[int, int]:
        i, j = np.searchsorted(weak, a), np.searchsorted(weak, b)
        return (weak[i - 1] if i > 0 else 0), (weak[j] if j < weak.size else t.size - 1)

    turns: dict[tuple[int, int], int] = {}
    for a, b in zip(keep_s, keep_e):
        lo, hi = stretch(a, b)
        k = a + int(np.argmax(np.abs(rate[a:b])))
        if (lo, hi) not in turns or abs(rate[k]) > abs(rate[turns[lo, hi]]):
            turns[lo, hi] = k
    if p.slow_turn_deg > 0:  # beyond the paper: a slow turn that still turns far
        for a, b in zip(*_runs(np.abs(rate) > p.threshold_rad_s / 2)):
            lo, hi = stretch(a, b)
            if (lo, hi) not in turns and abs(heading.gyro[hi] - heading.gyro[lo]) >= np.radians(
                p.slow_turn_deg
            ):
                turns[lo, hi] = a + int(np.argmax(np.abs(rate[a:b])))
    turns = dict(sorted(turns.items()))
    for (lo, hi), k in turns.items():
        angle = heading.gyro[hi] - heading.gyro[lo]
        if abs(angle) >= np.radians(p.min_angle_deg):
            out.append((t[k], TURN, t[hi], angle, t[lo]))
    return _drop_wiggles(out, p) if p.wiggle_deg > 0 else out


def _drop_wiggles(turns: list[tuple], p: GyroLandmarkParams) -> list[tuple]:
    """Runs of turns of alternating sign, each starting within ``merge_s`` of the previous
    one's end, whose net heading change is below ``wiggle_deg``: the phone swinging in the
    hand, not the walker turning. They are dropped."""
    out: list[tuple] = []
    i = 0
    while i < len(turns):
        j = i
        while (
            j + 1 < len(turns)
            and turns[j + 1][4] - turns[j][2] < p.merge_s
            and np.sign(turns[j + 1][3]) != np.sign(turns[j][3])
        ):
            j += 1
        group = turns[i : j + 1]
        net = sum(x[3] for x in group)
        if len(group) < 2 or abs(net) >= np.radians(p.wiggle_deg):
            out.extend(group)
        i = j + 1
    return out


def window_means(pressure: Scalar, window_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Non-overlapping window means p_i and each window's centre time."""
    t, v = pressure.t, pressure.value
    idx = np.floor((t - t[0]) / window_s).astype(np.int64)
    n = idx[-1] + 1
    cnt = np.bincount(idx, minlength=n)
    s = np.bincount(idx, weights=v, minlength=n)
    ok = cnt > 0
    centres = t[0] + (np.arange(n) + 0.5) * window_s
    return centres[ok], s[ok] / cnt[ok]


def detect_baro(pressure: Scalar | None, p: BaroLandmarkParams) -> list[Row]:
    if pressure is None or len(pressure) < 4:
        return []
    tc, pm = window_means(pressure, p.window_s)
    if pm.size < 3:
        return []
    d = np.diff(pm)  # d[j] = p_{j+1} - p_j
    sgn = (
        np.where(d > p.dead_band_hpa, 1, np.where(d < -p.dead_band_hpa, -1, 0))
        if p.dead_band_hpa > 0
        else np.sign(d).astype(int)
    )
    max_level = int(round(p.max_level_s / p.window_s)) if p.dead_band_hpa > 0 else 0
    out: list[tuple] = []  # (t, kind, t_end, value, t_start)
    runs = _sign_runs(sgn, max_level)
    for i0, i1, _ in runs:
        _floor_change(out, tc, pm, i0, i1, p)
    # a flight broken by a landing longer than max_level_s, or by one window of noise against
    # its sign: a run too small alone joined with the next run of the same sign when the
    # pressure between them is level, as one more candidate floor change (the association
    # chooses between it and the parts)
    bridge = BRIDGE_LEVELS * max(max_level, 1)
    for a, (a0, a1, sa) in enumerate(runs):
        b = a + 1  # the next run of the same sign, within reach (runs are in time order)
        while b < len(runs) and runs[b][2] != sa and runs[b][0] - a1 <= bridge:
            b += 1
        if b == len(runs) or runs[b][0] - a1 > bridge:
            continue
        b0, b1, _ = runs[b]
        a_alone, b_alone = (
            abs(pm[i1] - pm[i0]) > p.vertical_hpa for i0, i1 in ((a0, a1), (b0, b1))
        )
        if a_alone and b_alone or abs(pm[b0] - pm[a1]) >= p.horizontal_hpa:
            continue
        # the entry of a run that is a floor change alone is there already
        _floor_change(out, tc, pm, a0, b1, p, entry=not a_alone)
    return out


def _sign_runs(sgn: np.ndarray, max_level: int) -> list[tuple[int, int, int]]:
    """The runs of one sign of the windows' pressure changes (``sgn``, 0: level): (first
    window, last window, sign), a run grown while its sign holds, level windows tolerated up
    to ``max_level`` in a row."""
    runs: list[tuple[int, int, int]] = []
    j, n = 0, sgn.size
    while j < n:
        if sgn[j] == 0:
            j += 1
            continue
        s0, k, last, level = sgn[j], j, j, 0
        while k + 1 < n:
            if sgn[k + 1] == s0:
                last, level = k + 1, 0
            elif sgn[k + 1] == 0 and level < max_level:
                level += 1
            else:
                break
            k += 1
        runs.append((j, last + 1, int(s0)))  # the run goes from window p_j to p_{last + 1}
        j = last + 1
    return runs


# a flight's parts are joined across a level stretch up to this many times max_level_s
BRIDGE_LEVELS = 3


def _floor_change(
    out: list[Row],
    tc: np.ndarray,
    pm: np.ndarray,
    i0: int,
    i1: int,
    p: BaroLandmarkParams,
    entry: bool = True,
) -> None:
    """Eq. 4–6 for the run from window ``i0`` to ``i1``: an entry where it leaves a level
    stretch, an exit where it reaches one, when its total change exceeds ε_baro2."""
    change = pm[i1] - pm[i0]
    if abs(change) > p.vertical_hpa:
        level_before = i0 == 0 or abs(pm[i0] - pm[i0 - 1]) < p.horizontal_hpa
        level_after = i1 == pm.size - 1 or abs(pm[i1] - pm[i1 + 1]) < p.horizontal_hpa
        if level_before and entry:
            out.append((tc[i0], FLOOR_ENTRY, tc[i1], change, tc[i0]))
        if level_after:
            out.append((tc[i1], FLOOR_EXIT, tc[i1], change, tc[i0]))


def sections() -> tuple[str, ...]:
    """The rules' parameter sections, each once, in the table's order: one detector each."""
    return tuple(dict.fromkeys(r.params for r in TABLE))


def detector(section: str) -> Callable[..., list[Row]]:
    """The detector of a parameter section: ``detect_<section>`` of this module. Its first
    argument is named for what it reads — ``steps``, ``heading`` or ``pressure`` — its second
    is the section's parameters (None when :class:`.params.Params` has no such section)."""
    fn = globals().get(f"detect_{section}")
    if fn is None:
        raise WorkstationError(f"the landmark rules' section '{section}' (workstation/rules.py) "
                               f"has no detector: define detect_{section} in {__name__}")  # fmt: skip
    return fn


@functools.cache
def _reads(fn: Callable) -> str:
    """What a detector reads: its first argument's name."""
    return next(iter(inspect.signature(fn).parameters))


def detect_landmarks(
    steps: Steps, heading: Heading, pressure: Scalar | None, params: Params
) -> Detections:
    """Every rule's detections (:data:`.rules.TABLE`, each section's detector once), in time
    order."""
    sensors = {"steps": steps, "heading": heading, "pressure": pressure}
    rows: list[Row] = []
    for sec in sections():
        fn = detector(sec)
        rows += fn(sensors[_reads(fn)], getattr(params, sec, None))
    cols: list[tuple] = list(zip(*rows)) if rows else [()] * 5
    t = np.asarray(cols[0], float)
    kind = np.asarray(cols[1], dtype=f"<U{max(map(len, NAMES))}")
    t_end = np.asarray(cols[2], float)
    value = np.asarray(cols[3], float)
    t_start = np.asarray(cols[4], float)
    order = np.argsort(t, kind="stable")
    return Detections(t[order], kind[order], t_end[order], value[order], t_start[order])
