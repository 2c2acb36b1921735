"""Error statistics, one place for all of them (metrics, localize, evaluate).

Positions are compared in metres; a wrong floor is counted as ``FLOOR_PENALTY_M`` metres per
floor of error, as the IPIN/EvAAL competitions score (the 75th percentile of
error + 15 m × |floor error| is their score).
"""

from __future__ import annotations

import numpy as np

FLOOR_PENALTY_M = 15.0


def error_stats(err, floor_err=None, prefix: str = "") -> dict[str, float]:
    """mean/median/p75/p90 of horizontal errors ``err`` (m); with ``floor_err`` (floors, signed
    or not) also the floor accuracy, the mean with the floor penalty and the EvAAL score. Keys
    are ``{prefix}_mean_m`` etc. (no underscore when ``prefix`` is empty)."""
    e = np.asarray(err, float)
    e = e[np.isfinite(e)] if floor_err is None else e
    pre = f"{prefix}_" if prefix else ""
    if e.size == 0:
        return {}
    out = {
        f"{pre}mean_m": round(float(np.mean(e)), 3),
        f"{pre}median_m": round(float(np.median(e)), 3),
        f"{pre}p75_m": round(float(np.percentile(e, 75)), 3),
        f"{pre}p90_m": round(float(np.percentile(e, 90)), 3),
    }
    if floor_err is not None:
        fe = np.abs(np.asarray(floor_err, float))
        pen = e + FLOOR_PENALTY_M * fe
        out[f"{pre}floor_accuracy"] = round(float(np.mean(fe < 0.5)), 4)
        out[f"{pre}mean_with_floor_penalty_m"] = round(float(np.mean(pen)), 3)
        out[f"{pre}evaal_p75_m"] = round(float(np.percentile(pen, 75)), 3)
    return out
