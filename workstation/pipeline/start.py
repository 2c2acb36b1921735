"""Where a walk starts: a landmark id given by the user, or ``first-fix`` (the landmark at the
session's first ground-truth fix: for checking the tracker on walks with ground truth)."""

from __future__ import annotations

from ..errors import WorkstationError as StartError


def resolve_start(start: str, session, graph) -> str:
    """A node id, or ``first-fix``: the landmark at the session's first ground-truth fix."""
    import numpy as np

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
