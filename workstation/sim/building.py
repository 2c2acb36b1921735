"""Simulated buildings: floor plan, landmark graph, access points, named routes.

``office2f()`` is the paper-like sample: a two-floor office, 80 m × 50 m a floor (4,000 m²), a
ring corridor with corners (gyro landmarks), closed fire doors (accelerometer landmarks), a
stair (barometer entry/exit) and an elevator, and a ≈360 m survey route over both floors.

``office3f()`` is the same office on three unevenly spaced floors (3.1 m then 2.4 m: 0.37 and
0.29 hPa, as the museum's), with a staircase that climbs two floors in one flight (the survey
route takes it from floor 0 straight to floor 2) and the elevator serving all three.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.building.floorplan import Floor, FloorPlan
from workstation.graph import HPA_PER_M, Landmark, LandmarkGraph
from workstation.rules import FLOOR_CHANGE, STOP, TURN

FLOOR_HPA = 0.45  # pressure difference per floor (Table I, p_d)


@dataclass(frozen=True)
class AccessPoint:
    bssid: str
    ssid: str
    x: float
    y: float
    floor: float
    freq_mhz: float
    tx_dbm: float  # RSS at 1 m


@dataclass(frozen=True)
class Building:
    name: str
    plan: FloorPlan
    graph: LandmarkGraph
    access_points: tuple[AccessPoint, ...]
    routes: dict[str, tuple[str, ...]]
    doors: frozenset[str]  # nodes with a closed door: walk -> still -> walk
    elevators: frozenset[tuple[str, str]]  # inter-floor edges ridden standing still
    floor_height_m: float = 3.75
    seed: int = 0  # fixes the building (AP shadowing), independent of the walk's seed
    floor_levels_hpa: dict[float, float] | None = None  # drop from floor 0; None: 0.45 a floor

    def route_points(self, route: str | tuple[str, ...]) -> np.ndarray:
        """(N, 3) x, y, floor of a route's landmarks."""
        ids = self.routes[route] if isinstance(route, str) else route
        return np.array(
            [[self.graph.node(i).x, self.graph.node(i).y, self.graph.node(i).floor] for i in ids]
        )


def _wall(p, q, gaps=(), width=1.0) -> list[list[float]]:
    """Wall p→q as segments, leaving door openings of ``width`` centred at distances ``gaps``."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    length = float(np.hypot(*(q - p)))
    u = (q - p) / length
    cuts = [0.0]
    for g in sorted(gaps):
        cuts += [g - width / 2, g + width / 2]
    cuts.append(length)
    out = []
    for a, b in zip(cuts[0::2], cuts[1::2]):
        if b - a > 1e-6:
            pa, pb = p + a * u, p + b * u
            out.append([pa[0], pa[1], pb[0], pb[1]])
    return out


def _office_floor(f: int) -> Floor:
    w: list[list[float]] = []
    # building outline
    for p, q in [((0, 0), (80, 0)), ((80, 0), (80, 50)), ((80, 50), (0, 50)), ((0, 50), (0, 0))]:
        w += _wall(p, q)
    # ring corridor, centre line (10,10)-(70,40), 2.4 m wide; room doors every 10 m (open)
    room_doors_x = [15, 35, 45, 55, 65]
    stair_gap_y = 25 if f == 0 else 32
    w += _wall(
        (8.8, 8.8), (71.2, 8.8), gaps=[6.2, 16.2] + [x - 8.8 for x in (35, 45, 55, 65)], width=1.2
    )  # south outer, elevator gap at x=25
    w += _wall(
        (8.8, 41.2), (71.2, 41.2), gaps=[x - 8.8 for x in room_doors_x], width=1.0
    )  # north outer
    w += _wall((71.2, 8.8), (71.2, 41.2), gaps=[10, 22], width=1.0)  # east outer
    w += _wall((8.8, 8.8), (8.8, 41.2), gaps=[stair_gap_y - 8.8, 6], width=1.4)  # west outer
    w += _wall((11.2, 11.2), (68.8, 11.2), gaps=[8.8, 28.8, 48.8], width=1.0)  # core south
    w += _wall((11.2, 38.8), (68.8, 38.8), gaps=[8.8, 28.8, 48.8], width=1.0)  # core north
    w += _wall((11.2, 11.2), (11.2, 38.8), gaps=[13.8], width=1.0)  # core west
    w += _wall((68.8, 11.2), (68.8, 38.8), gaps=[13.8], width=1.0)  # core east
    # room partitions outside the ring (every 10 m) and inside the core
    for x in (20, 30, 50, 60):
        w += _wall((x, 0), (x, 8.8)) + _wall((x, 41.2), (x, 50))
    for y in (20, 30):
        w += _wall((71.2, y), (80, y))
    w += _wall((8.8, 36), (0, 36))  # north-west room
    w += _wall((30, 11.2), (30, 38.8)) + _wall((50, 11.2), (50, 38.8))
    # stair shaft (x 3.5..8.8, y 21..35) and elevator shaft (x 22.5..27.5, y 3.5..8.8)
    w += _wall((3.5, 21), (8.8, 21)) + _wall((3.5, 35), (8.8, 35)) + _wall((3.5, 21), (3.5, 35))
    w += (
        _wall((22.5, 3.5), (27.5, 3.5))
        + _wall((22.5, 3.5), (22.5, 8.8))
        + _wall((27.5, 3.5), (27.5, 8.8))
    )
    outline = np.array([[0, 0], [80, 0], [80, 50], [0, 50]], float)
    rooms = (
        ("corridor", np.array([[8.8, 8.8], [71.2, 8.8], [71.2, 41.2], [8.8, 41.2]], float)),
        ("core", np.array([[11.2, 11.2], [68.8, 11.2], [68.8, 38.8], [11.2, 38.8]], float)),
        ("stairs", np.array([[3.5, 21], [8.8, 21], [8.8, 35], [3.5, 35]], float)),
        ("elevator", np.array([[22.5, 3.5], [27.5, 3.5], [27.5, 8.8], [22.5, 8.8]], float)),
    )
    return Floor(np.array(w, float), outline, rooms)


def office2f(seed: int = 7) -> Building:
    """The paper-like two-floor office building."""
    return _office(seed, (0.0, 3.75), "office2f")


def office3f(seed: int = 11) -> Building:
    """Three unevenly spaced floors; a staircase straight from floor 0 to floor 2."""
    return _office(seed, (0.0, 3.1, 5.5), "office3f")


def _office(seed: int, heights: tuple[float, ...], name: str) -> Building:
    floors = list(range(len(heights)))
    graph = _office_graph(floors, name)
    routes = _office_routes(floors)
    plan = FloorPlan(name, {float(f): _office_floor(min(f, 1)) for f in floors})

    aps = _office_aps(floors, seed)
    elev = {(f"EL{a}", f"EL{b}") for a in floors for b in floors if a != b}
    levels = {float(f): h * HPA_PER_M for f, h in zip(floors, heights)}
    return Building(
        name=name,
        plan=plan,
        graph=graph,
        access_points=tuple(aps),
        routes=routes,
        doors=frozenset({f"D{side}{f}" for f in floors for side in "SN"}),
        elevators=frozenset(elev),
        floor_height_m=float(np.mean(np.diff(heights))),
        seed=seed,
        floor_levels_hpa=None if name == "office2f" else levels,
    )


def _office_graph(floors: list[int], name: str) -> LandmarkGraph:
    """The office's corridors on every floor, the stairs and the lift between them."""
    nodes: list[Landmark] = []
    edges: list[tuple[str, str]] = []

    def node(nid, x, y, f, rules, name):
        nodes.append(Landmark(nid, float(x), float(y), float(f), frozenset(rules), name))

    def link(*ids):
        for a, b in zip(ids, ids[1:]):
            edges.extend([(a, b), (b, a)])

    baro = set(FLOOR_CHANGE)
    for f in floors:
        node(f"SW{f}", 10, 10, f, {TURN}, f"south-west corner, floor {f}")
        node(f"SE{f}", 70, 10, f, {TURN}, f"south-east corner, floor {f}")
        node(f"NE{f}", 70, 40, f, {TURN}, f"north-east corner, floor {f}")
        node(f"NW{f}", 10, 40, f, {TURN}, f"north-west corner, floor {f}")
        node(f"DS{f}", 40, 10, f, {STOP}, f"south fire door, floor {f}")
        node(f"DN{f}", 40, 40, f, {STOP}, f"north fire door, floor {f}")
        node(f"ES{f}", 25, 10, f, {TURN}, f"elevator lobby turn, floor {f}")
        node(f"EL{f}", 25, 6, f, baro | {TURN}, f"elevator, floor {f}")
    node("W0", 10, 25, 0, {TURN}, "stair turn, floor 0")
    node("ST0", 6, 25, 0, baro | {TURN}, "stair bottom, floor 0")
    link("SW0", "ES0", "DS0", "SE0", "NE0", "DN0", "NW0", "W0", "SW0")
    link("W0", "ST0")
    for f in floors[1:]:
        node(f"ST{f}", 6, 32, f, baro | {TURN}, f"stair top, floor {f}")
        node(f"WU{f}", 10, 32, f, {TURN}, f"stair turn, floor {f}")
        link(
            f"SW{f}", f"ES{f}", f"DS{f}", f"SE{f}", f"NE{f}", f"DN{f}", f"NW{f}", f"WU{f}", f"SW{f}"
        )
        link(f"ST{f}", f"WU{f}")
        link(f"EL{f - 1}", f"EL{f}")
    link("ST0", "ST1")
    if len(floors) > 2:
        link("ST0", "ST2")  # one flight from floor 0 to floor 2 (past floor 1's landing)
    for f in floors:
        link(f"ES{f}", f"EL{f}")
    return LandmarkGraph(tuple(nodes), tuple(edges), source=name)


def _office_routes(floors: list[int]) -> dict[str, tuple[str, ...]]:
    """The walks the simulator takes through the office: the survey, reversed, floor 1's loop."""
    if len(floors) == 2:
        survey: tuple[str, ...] = (
            "W0", "SW0", "ES0", "DS0", "SE0", "NE0", "DN0", "NW0", "W0", "ST0", "ST1", "WU1",
            "NW1", "DN1", "NE1", "SE1", "DS1", "ES1", "EL1", "EL0", "ES0", "SW0",
        )  # fmt: skip
    else:
        survey = (
            "W0", "SW0", "ES0", "DS0", "SE0", "NE0", "DN0", "NW0", "W0", "ST0", "ST2", "WU2",
            "NW2", "DN2", "NE2", "SE2", "DS2", "ES2", "EL2", "EL1", "ES1", "SW1", "WU1", "NW1",
            "DN1", "NE1", "SE1", "DS1", "ES1", "EL1", "EL0", "ES0", "SW0",
        )  # fmt: skip
    return {
        "survey": survey,
        "reverse": tuple(reversed(survey)),
        "floor1": ("WU1", "SW1", "ES1", "DS1", "SE1", "NE1", "DN1", "NW1", "WU1", "SW1"),
    }


def _office_aps(floors: list[int], seed: int) -> list[AccessPoint]:
    """Twelve access points a floor, each a little off its spot (seeded)."""
    rng = np.random.default_rng(seed)
    aps = []
    spots = [
        (5, 5),
        (30, 5),
        (55, 5),
        (75, 15),
        (75, 45),
        (45, 45),
        (20, 45),
        (4, 42),
        (20, 25),
        (40, 25),
        (60, 25),
        (40, 16),
    ]
    for f in floors:
        for k, (x, y) in enumerate(spots):
            jx, jy = rng.uniform(-2, 2, 2)
            aps.append(
                AccessPoint(
                    bssid=f"02:0f:00:00:{f:02x}:{k:02x}",
                    ssid=f"office2f-{'ab'[k % 2]}",
                    x=float(x + jx),
                    y=float(y + jy),
                    floor=float(f),
                    freq_mhz=float((2412, 2437, 2462, 5180, 5240)[k % 5]),
                    tx_dbm=float(rng.uniform(-40, -34)),
                )
            )
    return aps


def grid_graph(n: int, spacing_m: float = 5.0) -> LandmarkGraph:
    """An n × n grid of landmarks on one floor, every third row and column crossing with a turn
    rule and the rest rule-less: the worst case for the route search (issue #18)."""
    nodes, edges = [], []
    for i in range(n):
        for j in range(n):
            rules = frozenset({TURN}) if i % 3 == 0 and j % 3 == 0 else frozenset()
            nodes.append(Landmark(f"n{i}_{j}", i * spacing_m, j * spacing_m, 0.0, rules, None))
            if i:
                edges += [(f"n{i}_{j}", f"n{i - 1}_{j}"), (f"n{i - 1}_{j}", f"n{i}_{j}")]
            if j:
                edges += [(f"n{i}_{j}", f"n{i}_{j - 1}"), (f"n{i}_{j - 1}", f"n{i}_{j}")]
    return LandmarkGraph(tuple(nodes), tuple(edges))


BUILDINGS = {"office2f": office2f, "office3f": office3f}
