"""The organizers' waypoint-anchored PDR (Microsoft ILC 2020 ``compute_step_positions``, written
here from its description): between two consecutive taps, the dead-reckoned path (fixed step
length, gyro heading — eq. 7–8) is rotated and scaled so that it starts on the first tap and
ends on the next; every scan is then placed on that path. It needs the taps, as tap
interpolation does, but follows the walker's turns between them.

Per leg, as complex numbers: with ``Z(t)`` the dead-reckoned position, the leg's map is
``w(t) = w_a + (w_b − w_a) / (Z(t_b) − Z(t_a)) · (Z(t) − Z(t_a))`` — one rotation and one scale.
A leg along which the walker did not move (``|Z(t_b) − Z(t_a)|`` under a step) is interpolated
in time between its taps.
"""

from __future__ import annotations

import numpy as np

from workstation.baselines import Trajectory
from workstation.baselines.pdr import step_headings
from workstation.baselines.tap import taps_from_session
from workstation.params import GYRO_HEADING, Params
from workstation.session.model import sample_path


def waypoint_pdr(session, params: Params | None = None, graph=None) -> Trajectory:
    params = params or Params()
    tt, tx, ty, tf = taps_from_session(session, graph)
    t, theta = step_headings(session, params, GYRO_HEADING)
    st = t[(t >= tt[0]) & (t <= tt[-1])]
    if tt.size < 2 or st.size == 0:
        return Trajectory(st, *sample_path(tt, tx, ty, tf, st))
    th = np.interp(st, t, np.unwrap(theta)) if t.size else np.zeros(st.size)
    step = params.pdr.initial_step_length_m
    zs = np.concatenate([[0], np.cumsum(step * np.exp(1j * th))])  # Z after each step
    ts = np.concatenate([[tt[0]], st])

    def Z(times):
        return np.interp(times, ts, zs.real) + 1j * np.interp(times, ts, zs.imag)

    za, zb = Z(tt[:-1]), Z(tt[1:])
    wa, wb = tx[:-1] + 1j * ty[:-1], tx[1:] + 1j * ty[1:]
    moved = np.abs(zb - za) >= step
    c = np.where(moved, (wb - wa) / np.where(moved, zb - za, 1.0), 0.0)
    leg = np.clip(np.searchsorted(tt, st, side="right") - 1, 0, tt.size - 2)
    w = wa[leg] + c[leg] * (Z(st) - za[leg])
    lin_x, lin_y, f = sample_path(tt, tx, ty, tf, st)
    w = np.where(moved[leg], w, lin_x + 1j * lin_y)
    return Trajectory(st, w.real, w.imag, f)
