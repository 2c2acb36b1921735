"""Which detection is which landmark (beyond the paper: docs/decisions.md).

- ``greedy`` (the paper, §III-B): each detection in turn is matched to its most confident
  candidate above ε_v (eq. 11–14), or ignored; a wrong match is never revisited.
- ``hmm`` (the default): the survey is offline, so the association is chosen to explain the
  whole walk, as HMM map matching does for GPS traces. A hypothesis is a chain of matches; at
  each detection every hypothesis may ignore it or match one of its candidates, and gains the
  candidate's log-likelihood (distance walked against the path length, direction walked against
  the direction to the landmark, pressure change against the floor spacing, minus a cost per
  detectable landmark passed without a detection, plus ``match_gain`` for explaining a
  detection). Hypotheses at the same landmark reached at the same step are merged (Viterbi);
  the ``beam_width`` best live on. Each hypothesis carries its own step length, gyro offset and
  floor spacings, learnt from its matches. With no start given, every landmark starts a
  hypothesis and the search is widened until ``start_search_s`` after the walk starts — one pass,
  not one run per landmark.
"""

from __future__ import annotations

from workstation.pipeline.tracking.candidates import Candidate
from workstation.pipeline.tracking.state import TrackerState, WalkToDetection
from workstation.pipeline.tracking.tracker import Tracker

MAX_START_WIDTH = 1024


def associate(trk: Tracker, starts: list[str]) -> list[TrackerState]:
    """The surviving chains of matches from ``starts``, best first (for ``greedy``: one chain
    per start, ranked by matches, then summed confidence)."""
    if trk.p.association == "greedy":
        ranked = []
        for s in starts:
            st = greedy(trk, trk.start(s))
            ranked.append(((len(st.matches), sum(m.confidence for m in st.matches)), st))
        ranked.sort(key=lambda r: r[0], reverse=True)  # stable: the first start wins ties
        return [st for _, st in ranked]
    return hmm(trk, starts)


def greedy(trk: Tracker, st: TrackerState) -> TrackerState:
    det = trk.det
    for k in range(len(det)):
        if trk.still_at_anchor(st, k):
            continue
        w = trk.walk_to_detection(st, k)
        cands, _ = trk.scoring.candidates(st, k, w)
        c = trk.scoring.paper_choice(cands)
        if c is not None:
            st = trk.advance(st, k, c, w)
    return st


def hmm(trk: Tracker, starts: list[str]) -> list[TrackerState]:
    p, det = trk.p, trk.det
    states = [trk.start(s) for s in starts]
    width = p.beam_width
    # while the start is searched: 4 hypotheses per landmark, at most MAX_START_WIDTH (on a graph
    # of thousands of landmarks the first detections already prune most starts)
    wide = max(width, min(4 * len(starts), MAX_START_WIDTH)) if len(starts) > 1 else width
    for k in range(len(det)):
        tk = float(det.t[k])
        if tk <= trk.t0:
            continue
        # every hypothesis may ignore detection k, or match one of its best candidates; the
        # best per (landmark, step) survives (Viterbi), and only the survivors are built
        best: dict[
            tuple[str, int],
            tuple[float, TrackerState | tuple[TrackerState, Candidate, WalkToDetection]],
        ] = {}
        for st in states:
            key = (st.node, st.a_idx)
            if key not in best or st.score > best[key][0]:
                best[key] = (st.score, st)
        for st in states:
            if trk.still_at_anchor(st, k):
                continue
            w = trk.walk_to_detection(st, k)
            cands, _ = trk.scoring.candidates(st, k, w)
            for c in cands[:4]:
                key, score = (c.node, w.i_end), st.score + c.score
                if key not in best or score > best[key][0]:
                    best[key] = (score, (st, c, w))
        keep = wide if tk < trk.t0 + p.start_search_s else width
        top = sorted(best.values(), key=lambda v: -v[0])[:keep]
        states = [
            v if isinstance(v, TrackerState) else trk.advance(v[0], k, v[1], v[2]) for _, v in top
        ]
    return sorted(states, key=lambda s: -s.score)
