"""Two recordings joined with every clock re-timed (issue #67 item 2, beyond the paper): the
compass and the gyroscope disagree about a turn.

The gyroscope's heading :math:`\\psi_g(t)` (rate about gravity, integrated: relative) and the
tilt-compensated compass :math:`\\psi_c(t)` (absolute) of one recording differ by a slowly
moving offset :math:`o(t) = \\psi_c(t) - \\psi_g(t)`: the gyroscope's unknown starting
heading, its bias, and the building's magnetic disturbances. A phone turned in the hand turns
both alike. Where a second recording is joined on, the gyroscope's integral runs on from the
first walk's last heading while the compass reads the second walk's: :math:`o` jumps by the
difference of the two headings — an angle no walker's turn explains.

The jump at :math:`\\tau` is the angle between the circular means of :math:`e^{i o}` over the
``WINDOW_S`` before and after it,

.. math:: \\Delta(\\tau) = \\left|\\arg\\frac{\\bar z_+(\\tau)}{\\bar z_-(\\tau)}\\right|,
          \\qquad \\bar z_\\pm = \\operatorname{mean}_{t \\in W_\\pm(\\tau)} e^{i o(t)},

counted only where the offset is steady on both sides (:math:`|\\bar z_\\pm| \\ge`
``STEADY``: no magnetic storm) and the phone is held alike on both sides (the mean gravity
direction in the phone's frame moves less than ``HOLD_DEG``: a phone taken out of a pocket
turns its compass axis without a turn about gravity), and not across a change of floor (the
barometer's mean moves less than ``FLOOR_HPA`` between the windows: a lift's steel car or a
stair's rebar turns the compass for as long as the ride — the simulated office's zones do, by
78–93°; a join across floors the barometer already refuses, session/sanity.py).

Measured (docs/experiments.md, "Two walks joined with every clock re-timed"): over the 482
real walks here (the mall's four floors and its samples, the museum) the largest
:math:`\\Delta` is 66°; a join's is uniform on 0–180° where both sides are steady.
``JUMP_DEG`` = 90° flags none of them and about half of the mall's joins.
"""

from __future__ import annotations

import math

import numpy as np

from workstation.params import HeadingParams, Params
from workstation.pipeline.heading import Heading, estimate_heading
from workstation.session import Scalar, Session, Vector3

#: the offset's jump that a join, not a walk, makes (°; real walks here: 66° at most)
JUMP_DEG = 90.0
#: each side's window (s): long enough that steps and short magnetic disturbances average out
WINDOW_S = 10.0
#: the least resultant length of the offset's unit vectors on each side (1: one offset)
STEADY = 0.7
#: the phone held alike on both sides: mean gravity directions within this (°)
HOLD_DEG = 20.0
#: a change of floor between the two windows (hPa; a floor is 0.4–0.5)
FLOOR_HPA = 0.2
#: the moments compared, every this many seconds
STEP_S = 0.5


def facing_jump(
    heading: Heading, acc: Vector3, pressure: Scalar | None = None
) -> tuple[float, float] | None:
    """Where the compass-minus-gyroscope offset jumps by ``JUMP_DEG`` or more, and by how much:
    (the moment on the session's clock, degrees) of the largest jump; None when there is none
    (or the walk is shorter than two windows, or has no compass)."""
    t = heading.t
    ok = np.isfinite(heading.compass)
    if t.size < 2 or len(acc) < 2 or not ok.any() or t[-1] - t[0] < 2 * WINDOW_S:
        return None
    z = np.where(ok, np.exp(1j * np.where(ok, heading.compass - heading.gyro, 0.0)), 0.0)
    tau = np.arange(t[0] + WINDOW_S, t[-1] - WINDOW_S + 1e-9, STEP_S)
    before = _window_means(t, z, ok, tau - WINDOW_S, tau)
    after = _window_means(t, z, ok, tau, tau + WINDOW_S)
    up = acc.xyz / np.maximum(np.linalg.norm(acc.xyz, axis=1, keepdims=True), 1e-9)
    everywhere = np.ones(acc.t.size, bool)
    ua = _window_means(acc.t, up, everywhere, tau - WINDOW_S, tau)
    ub = _window_means(acc.t, up, everywhere, tau, tau + WINDOW_S)
    cos_hold = np.einsum("ij,ij->i", ua, ub) / np.maximum(
        np.linalg.norm(ua, axis=1) * np.linalg.norm(ub, axis=1), 1e-12
    )
    jump = np.degrees(np.abs(np.angle(after * np.conj(before))))
    level = np.ones(tau.size, bool)
    if pressure is not None and len(pressure) >= 2:
        fin = np.isfinite(pressure.value)
        pa = _window_means(pressure.t, pressure.value, fin, tau - WINDOW_S, tau)
        pb = _window_means(pressure.t, pressure.value, fin, tau, tau + WINDOW_S)
        level = np.abs(pb - pa) < FLOOR_HPA
    counted = (
        level
        & (np.abs(before) >= STEADY)
        & (np.abs(after) >= STEADY)
        & (cos_hold >= math.cos(math.radians(HOLD_DEG)))
        & (jump >= JUMP_DEG)
    )
    if not counted.any():
        return None
    k = int(np.argmax(np.where(counted, jump, -1.0)))
    return float(tau[k]), float(jump[k])


def facing_jump_of(
    session: Session, p: HeadingParams | None = None
) -> tuple[float, float] | None:
    """:func:`facing_jump` of a session as it was read (its heading estimated with ``p``, the
    defaults when not given): what ``workstation split`` and the joins benchmark look for."""
    heading = estimate_heading(session, p if p is not None else Params().heading)
    return facing_jump(heading, session.accelerometer, session.pressure)


def _window_means(
    t: np.ndarray, v: np.ndarray, ok: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> np.ndarray:
    """The mean of ``v`` (rows where ``ok``) over ``lo <= t < hi`` for each window, from
    cumulative sums (0 for a window holding none)."""
    w = np.where(ok.reshape(-1, *([1] * (v.ndim - 1))), v, 0)
    c = np.concatenate([np.zeros((1, *v.shape[1:]), w.dtype), np.cumsum(w, axis=0)])
    n = np.concatenate([[0], np.cumsum(ok)])
    i, j = np.searchsorted(t, lo), np.searchsorted(t, hi)
    cnt = (n[j] - n[i]).astype(float)
    shape = (-1, *([1] * (v.ndim - 1)))
    return (c[j] - c[i]) / np.maximum(cnt, 1.0).reshape(shape)
