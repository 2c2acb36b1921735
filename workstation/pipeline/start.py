"""When a walk starts (the end of the initial stand) and where: a landmark id given by the user, or ``first-fix`` (the landmark at the
session's first ground-truth fix: for checking the tracker on walks with ground truth)."""

from __future__ import annotations

import numpy as np

from ..errors import WorkstationError as StartError
from ..params import PDRParams


def resolve_start(start: str, session, graph) -> str | None:
    """A node id, ``first-fix``: the landmark at the session's first ground-truth fix, or
    ``infer``: None (the tracker infers it)."""

    if start == "infer":
        return None
    if start != "first-fix":
        if start not in graph.ids:
            raise StartError(f"--start {start}: no such landmark in the graph")
        return start
    gt = session.ground_truth
    if gt is None or not len(gt):
        raise StartError("--start first-fix: the session has no ground truth")
    if graph.frame is not None and session.frame is not None:
        gt = session.in_frame(graph.frame).ground_truth
    xyf = graph.xyf()
    d = np.hypot(xyf[:, 0] - gt.x[0], xyf[:, 1] - gt.y[0]) + np.where(
        xyf[:, 2] == gt.floor[0], 0, 1e9
    )
    return graph.ids[int(np.argmin(d))]


def find_start_time(steps, p: PDRParams) -> float:
    """End of the first still period of ``start_still_s`` within ``start_search_s`` (else 0)."""
    t, walking = steps.state_t, steps.walking
    if t.size < 2 or p.start_still_s <= 0:
        return float(t[0]) if t.size else 0.0
    d = np.diff(np.concatenate([[1], walking.astype(np.int8), [1]]))
    s, e = np.flatnonzero(d == -1), np.flatnonzero(d == 1)
    found = None
    for a, b in zip(s, e):
        if t[a] > t[0] + p.start_search_s:
            break
        end = float(t[min(b, t.size) - 1])
        if found is not None and t[a] - found < p.start_still_s / 2:
            found = end  # a brief movement inside the initial stand (phone handling): same stand
            continue
        if found is None and end - t[a] >= p.start_still_s and b < t.size:
            found = end
        elif found is not None:
            break
    return found if found is not None else float(t[0])
