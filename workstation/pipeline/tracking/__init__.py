"""The tracking stage (§III-B, eq. 7–14): landmark-graph PDR.

- :mod:`.state` — the types every part reads: :class:`Track`, the chain of matches
  (:class:`TrackerState`, :class:`Match`), the walk to a detection; at the bottom.
- :mod:`.candidates` — scoring a detection's candidate landmarks (eq. 11–14).
- :mod:`.tracker` — the engine: dead reckoning from an anchor (eq. 7–8), advancing a chain at a
  match (eq. 10).
- :mod:`.association` — which detection is which landmark (greedy as the paper; whole-walk).
- :mod:`.replay` — the chosen chain turned into a :class:`Track`.
- :mod:`.map_prior`, :mod:`.open_by_map` — a building's radio map as evidence (beyond the paper).
- :mod:`.walk_end` — closing the walk's end on a landmark (beyond the paper).
- :mod:`.run` — :func:`track`, the stage: all of the above in order.

This face imports nothing: importing any part of the package runs it, and a face that loaded
:mod:`.run` made every module reading :class:`Track` load the whole stage (and its circle).
"""
