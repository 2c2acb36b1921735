"""The landmark graph (paper §III-B): landmarks with their detection rules, and walkable edges.

YAML schema::

    frame: {origin_lat: 49.461, origin_lon: 11.111}   # optional: where x/y come from
    floors: {0: 0.0, -1: -3.1, -2: -5.8}             # optional: floor heights (m), a building fact
    landmark_sigma_m: 1.5    # optional: how far a walker at a landmark may be from its point (m)
    nodes:
      - {id: L01, x: 12.3, y: -4.0, floor: 0, rules: [gyro], name: "corner by the lift"}
      - {id: L02, x: 20.1, y: -4.0, floor: 0, rules: [acc]}
    edges:
      - {from: L01, to: L02}                # both directions (the default)
      - {from: L02, to: L03, oneway: true}  # only L02 -> L03

``landmark_sigma_m``: a landmark drawn on the plan where the walker turns or stops is known to
about half a metre (the default, :data:`.pipeline.sigma.BASE_M`); one drawn from many walks'
taps (``graph from-waypoints``) only as well as the taps it merged, up to
:data:`workstation.walks.graph_from_walks.CLUSTER_M` apart. Placement σ (:mod:`.pipeline.sigma`) starts from it.

Rules: ``acc`` (walk → still → walk, eq. 2), ``gyro`` (turn, eq. 3), ``baro_entry`` and
``baro_exit`` (start/end of a floor change, eq. 4–6). Each directed edge carries its heading
(rad, counter-clockwise from +x = east) and horizontal length (m), derived from the coordinates.
"""

from workstation.graph.model import (
    BARO_RULES,
    HPA_PER_M,
    MIN_EDGE_LENGTH_M,
    RULES,
    Landmark,
    LandmarkGraph,
)

__all__ = ["BARO_RULES", "HPA_PER_M", "MIN_EDGE_LENGTH_M", "RULES", "Landmark", "LandmarkGraph"]
