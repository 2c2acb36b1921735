"""Two recordings on one clock (issue #55 item 6, beyond the paper): the evidence a reader finds
that a file holds two walks re-timed to follow each other with no pause between them.

A pause of the inertial sensors (``sensor_hole``) is what a join leaves unless whoever joined
the files closed it; closed, the sensors do not tell (docs/experiments.md#a-pause-of-the-
inertial-sensors). A file's second clock does — the one the joiner did not re-time:

- GetSensorData (IPIN) records carry the sensor's own timestamp beside the app's. In one
  recording the two differ by a constant (the 10 museum walks: no sample farther than 1 s from
  it); a second recording re-timed on the app clock keeps its own offset, so a whole block of
  samples disagrees.
- Microsoft ILC WiFi readings carry the time the access point was last seen, which is never
  after the scan that reports it (the 106 mall walks: 116 ms before it at the least), and each
  scan hears some access point afresh; a second recording moved earlier to follow the first
  has scans reporting access points seen after them, one moved later by over 10 min scans
  whose every access point was seen that long before.

A file carries one more record of the recording it came from: the phone's own state. A
Microsoft ILC file's uncalibrated magnetometer rows report, beside the raw field, the hard-iron
bias the phone subtracted to calibrate it. The phone holds one estimate through a recording
(450 of the 451 walks of the mall's four floors; the other re-estimated it once, by 3.6 µT,
while its raw field ran on: 1 µT between the two samples) and re-estimates it between
recordings (two walks of one floor: a different estimate in 85 % of pairs, the same in 97 % of
walks recorded one after the other). Where a block of samples reports another estimate (by
more than ``BIAS_TOL_UT``) *and* the raw field jumps there (by ``RAW_JUMP_UT`` or more: a
re-estimate leaves the raw field as it was, a second recording begins elsewhere, facing
elsewhere — 97 % of those pairs), a second recording begins (:func:`calibration_change`).

A file carries its phone's hardware, too. A magnetometer reports whole steps of its resolution
(the museum's two phones: 0.06 and 0.1 µT; GetSensorData writes them as read), so every change
between two of its samples is a whole number of steps — in every block of every real walk here,
through the phone's own re-calibrations, which move the field, not its steps. A block whose
changes leave that grid, themselves on another step, is another phone's sensor
(:func:`resolution_change`): half the museum's joins are of its two phones. A stream written as
floats off any grid (the mall's: steps of 10⁻⁵ µT, no whole multiples) says nothing.

The evidence is kept in the session's ``metadata.clock_jump``: ``t`` (on the session's
clock, where the second recording begins) and ``what`` (which records, how many); the run's
verdict quarantines the walk (``two_clocks``) and ``workstation split`` cuts it there.
"""

from __future__ import annotations

import numpy as np

from workstation.session.metadata import ClockJump
from workstation.session.model import Vector3

#: a block of at least this many samples (and 1 % of the stream) on another clock is a second
#: recording; fewer are a sensor's glitch, re-timed from the app clock with a warning
MIN_BLOCK = 10
#: of WiFi scans, two in a row (a walk holds 7–56): no real scan reports a reading from after it
MIN_SCANS = 2
#: a WiFi reading seen more than this after its own scan, or more than ``PAST_MS`` before it
#: (ms), cannot be of that recording
FUTURE_MS = 1000.0
PAST_MS = 600_000.0
#: the phone's magnetometer bias estimate (µT) reported by another recording: beyond this
BIAS_TOL_UT = 0.5
#: … and the raw field jumps by at least this (µT) between the two samples either side (a
#: walk's own raw field moves 6 µT at most between two samples, median walk; 52 at the most)
RAW_JUMP_UT = 10.0
#: a magnetometer's resolution (µT) is read from the changes between its samples when the
#: smallest is at least this (finer: a float stream's noise, no grid) …
MIN_STEP_UT = 0.01
#: … and 98 % of them lie within this share of a step of a whole number of steps
GRID_TOL = 0.02
#: samples the opening (or closing) grid is read from, and per block counted against it: a
#: block whose changes are mostly (half or more of at least ``GRID_MIN_MOVES``) off the grid
GRID_OPEN = 250
GRID_BLOCK = 100
GRID_MIN_MOVES = 20
#: … for this many blocks in a row (6 s at 50 Hz) is another sensor
GRID_RUN = 3
#: how the reader's warning begins (a part cut off by ``split`` drops it with the evidence)
SAID = "a second recording begins at"


def block_start(t: np.ndarray, off: np.ndarray, least: int = MIN_BLOCK) -> float | None:
    """Where the samples ``off`` (on another clock) form a second recording: their longest run,
    if it holds ``least`` samples and 1 % of the stream, is one recording — the other begins
    where it ends when it opens the stream, else where it begins (``t`` sorted). None for a
    few stray ones, or a stream all on one clock."""
    run = _longest_run(off, least)
    return None if run is None else _begins(t, off.size, run)


def second_clock(t: np.ndarray, offset: np.ndarray, tol: float) -> tuple[float, int] | None:
    """Where a second recording begins in a stream whose samples carry two clocks (``offset``:
    the app's less the sensor's, ``t`` sorted): a block on another offset than the opening
    samples', itself on *one* offset (90 % within ``tol`` of its median) — a sensor clock that
    drifts or is garbage moves all the time, and is no second recording. Returns where, and
    how many samples the block holds."""
    off = np.abs(offset - np.median(offset[:MIN_BLOCK])) > tol
    run = _longest_run(off, MIN_BLOCK)
    if run is None:
        return None
    block = offset[run[0] : run[1]]
    if np.mean(np.abs(block - np.median(block)) <= tol) < 0.9:
        return None
    at = _begins(t, off.size, run)
    return None if at is None else (at, block.size)


def calibration_change(
    t: np.ndarray, raw: np.ndarray, bias: np.ndarray
) -> tuple[float, str] | None:
    """Where a second recording begins by the phone's state (module doc): ``t`` sorted, the
    uncalibrated magnetometer's ``raw`` field and the ``bias`` the phone reported with it
    (N, 3; µT). A block of samples whose bias differs from the opening sample's by more than
    ``BIAS_TOL_UT`` (:func:`block_start`), where the raw field jumps by ``RAW_JUMP_UT`` or more
    between the last sample before the block's edge and the first after. None else."""
    if t.size < 2:
        return None
    changed = np.linalg.norm(bias - bias[0], axis=1) > BIAS_TOL_UT
    at = block_start(t, changed)
    if at is None:
        return None
    i = int(np.clip(np.searchsorted(t, at), 1, t.size - 1))
    jump = float(np.linalg.norm(raw[i] - raw[i - 1]))
    if jump < RAW_JUMP_UT:
        return None
    moved = float(np.linalg.norm(bias[i] - bias[i - 1]))
    return at, (f"the phone's magnetometer calibration changes by {moved:.1f} µT where its raw "
                f"field jumps {jump:.0f} µT: another recording's phone state")  # fmt: skip


def step_of(v: np.ndarray) -> float | None:
    """The resolution of a sensor whose values ``v`` (N, 3) lie on a grid: the smallest change
    between two samples on any axis, when at least ``MIN_STEP_UT`` and all but 2 % of the
    changes are whole multiples of it (``GRID_TOL``) over at least ``GRID_MIN_MOVES``; else
    None (values off any grid)."""
    d = np.abs(np.diff(v, axis=0)).ravel()
    d = d[d > 1e-9]
    if d.size < GRID_MIN_MOVES or d.min() < MIN_STEP_UT:
        return None
    q = float(d.min())
    return q if np.mean(_on(d, q)) >= 1.0 - GRID_TOL else None


def resolution_change(t: np.ndarray, xyz: np.ndarray) -> tuple[float, str] | None:
    """Where another phone's magnetometer begins (module doc): ``t`` sorted, ``xyz`` (N, 3) µT.
    The opening samples' grid (:func:`step_of`), then ``GRID_RUN`` blocks in a row whose changes
    leave it, themselves on a grid of another step; or the same from the closing samples back
    (a finer sensor after a coarser one whose step it divides). None else."""
    if t.size < GRID_OPEN + GRID_RUN * GRID_BLOCK:
        return None
    for v, flip in ((xyz, False), (xyz[::-1], True)):
        q0 = step_of(v[:GRID_OPEN])
        if q0 is None:
            continue
        k = _leaves(v, q0)
        if k is None:
            continue
        q1 = step_of(v[k : k + GRID_RUN * GRID_BLOCK])
        if q1 is None or abs(q1 / q0 - 1.0) <= GRID_TOL:
            continue
        first, then = (q1, q0) if flip else (q0, q1)
        at = float(t[t.size - k] if flip else t[k])
        return at, (f"the magnetometer's resolution changes from {first:.3g} to {then:.3g} µT: "
                    "another phone's sensor")  # fmt: skip
    return None


def another_sensor(magnetometer: Vector3) -> list[tuple[float, str]]:
    """The readers' evidence from a magnetometer stream: :func:`resolution_change`'s finding,
    as a list of it (empty when none)."""
    found = resolution_change(magnetometer.t, magnetometer.xyz)
    return [] if found is None else [found]


def _on(d: np.ndarray, q: float) -> np.ndarray:
    r = d / q
    return np.asarray(np.abs(r - np.round(r)) <= GRID_TOL)


def _leaves(v: np.ndarray, q: float) -> int | None:
    """The first sample of the first run of ``GRID_RUN`` blocks whose changes mostly leave the
    grid of step ``q`` (the sample after the first change off it, from the block before on)."""
    d = np.abs(np.diff(v, axis=0))
    moved: np.ndarray = d > 1e-9
    off: np.ndarray = np.any(moved & ~_on(d, q), axis=1)
    any_move: np.ndarray = np.any(moved, axis=1)
    n = d.shape[0] // GRID_BLOCK
    counts = any_move[: n * GRID_BLOCK].reshape(n, GRID_BLOCK).sum(axis=1)
    offs = off[: n * GRID_BLOCK].reshape(n, GRID_BLOCK).sum(axis=1)
    bad = (counts >= GRID_MIN_MOVES) & (2 * offs >= counts)
    runs = np.convolve(bad.astype(int), np.ones(GRID_RUN, int), "valid") == GRID_RUN
    if not runs.any():
        return None
    b = int(np.argmax(runs))
    lo = max(b - 1, 0) * GRID_BLOCK
    return lo + int(np.argmax(off[lo:])) + 1


def _longest_run(off: np.ndarray, least: int) -> tuple[int, int] | None:
    """The longest run [start, end) of ``off``, if it holds ``least`` and 1 % of the samples."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], off.astype(np.int8), [0]])))
    if not edges.size:
        return None
    starts, ends = edges[::2], edges[1::2]
    k = int(np.argmax(ends - starts))
    if ends[k] - starts[k] < max(least, 0.01 * off.size):
        return None
    return int(starts[k]), int(ends[k])


def _begins(t: np.ndarray, n: int, run: tuple[int, int]) -> float | None:
    """Where the recording other than the run's opening stream begins: the run's start, or
    its end when it opens the stream (None: the run is the whole stream)."""
    if run[0] > 0:
        return float(t[run[0]])
    return float(t[run[1]]) if run[1] < n else None


def first_jump(found: list[tuple[float, str]], warnings: list[str]) -> ClockJump | None:
    """The earliest of the evidence ``(t, what)`` found in a file's records (and said among the
    reader's ``warnings``: ``info`` and ``run`` print them first)."""
    if not found:
        return None
    t, what = min(found)
    warnings.append(f"{SAID} {t:.1f} s ({what}): two walks joined into "
                    "one file? (workstation split cuts it there)")  # fmt: skip
    return ClockJump(round(t, 3), what)
