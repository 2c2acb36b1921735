"""Tap interpolation: the surveyor taps at known points and positions are interpolated in time
between taps (what common survey apps do). On real walks the taps are the POSI fixes, so this is
an oracle; on simulated walks they are the landmark passes."""

from __future__ import annotations

import numpy as np

from workstation.baselines import Trajectory
from workstation.session.model import sample_path


def taps_from_session(session, graph=None):
    """(t, x, y, floor) of the taps: the simulator's landmark passes, else the ground-truth fixes."""
    passes = session.metadata.extra.get("landmark_passes")
    if passes and graph is not None:
        t = np.array([p[0] for p in passes], float)
        nodes = [graph.node(p[1]) for p in passes]
        return (
            t,
            np.array([n.x for n in nodes]),
            np.array([n.y for n in nodes]),
            np.array([n.floor for n in nodes]),
        )
    gt = session.ground_truth
    return gt.t, gt.x, gt.y, gt.floor


def tap_interpolation(session, step_times: np.ndarray, graph=None) -> Trajectory:
    t, x, y, f = taps_from_session(session, graph)
    st = step_times[(step_times >= t[0]) & (step_times <= t[-1])]
    return Trajectory(st, *sample_path(t, x, y, f, st))
