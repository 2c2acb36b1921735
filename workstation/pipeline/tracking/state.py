"""The tracker's state types (§III-B): the corrected trajectory it produces (:class:`Track`),
a chain of matches (:class:`Match`, :class:`TrackerState`), the dead reckoning from the last
matched landmark to a detection (:class:`WalkToDetection`, eq. 7–8), and what a building's map
changed (:class:`Reranked`, :class:`OpenFit`). The bottom of the tracking package: every other
module of it reads these, and this one reads none of them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, NamedTuple

import numpy as np

from workstation.pipeline.floors import FloorModel
from workstation.pipeline.reach import Route
from workstation.pipeline.start import StartTimeHow
from workstation.session import Scalar
from workstation.session.model import Times, sample_path

# an inferred start whose best alternative elsewhere is less than this many log-likelihood units
# (e^3 ≈ 20×) less likely is reported ambiguous: the surveyor should give --start; the chains
# the sensors cannot tell apart by more (the map re-ranks them, a given end chooses among them)
START_AMBIGUOUS_MARGIN = 3.0
#: an end closed on a landmark (walk_end.py) with σ at most this checks the walk as a match
#: does: placed as tightly as a reference point was allowed to be before session 19 (3 m; the
#: default radiomap.max_sigma_m is 3.5 m since: the quarantine check was not loosened with it).
#: Here, at the bottom of tracking, for every stage that asks (the tracker, σ, the radio map,
#: the verdict).
END_CHECK_M = 3.0


@dataclass(frozen=True)
class Reranked:
    """What the map changed: the chain chosen's place among the distinct chains by the sensors
    alone (0: the sensors' best), how many were compared, and the chosen chain's gain in
    log-likelihood over the sensors' best (map term included)."""

    rank: int = 0
    chains: int = 0
    gain: float = 0.0
    sensors: float = 0.0  # how much less likely the chosen chain is by the sensors alone


class OpenFit(NamedTuple):
    """How a walk that matched nothing was turned (degrees, counter-clockwise) and scaled, on
    how many scans; 0° and ×1: the map was not decisive; ``scans`` 0: not tried."""

    turn_deg: float = 0.0
    scale: float = 1.0
    scans: int = 0


#: how the walk's end was taken (walk_end.HOW says each in words)
EndHow = Literal["closed", "at_last_match", "ambiguous", "far", "off", "given", "given_far"]


@dataclass(frozen=True)
class Steps:
    """The corrected trajectory, one row per step."""

    t: np.ndarray
    x: np.ndarray  # forward, as the paper: snapped at each matched landmark
    y: np.ndarray
    floor: np.ndarray
    heading: np.ndarray
    step_length: np.ndarray
    segment: np.ndarray  # segment index per step (-1 = before the walk starts)
    x_bc: np.ndarray  # backward-corrected: each closed segment bent to end on its landmark
    y_bc: np.ndarray
    raw_x: np.ndarray  # plain PDR from the start landmark (no graph after the start)
    raw_y: np.ndarray


@dataclass(frozen=True)
class Detections:
    """What the tracker made of each landmark detection, one row per detection."""

    node: np.ndarray  # matched node id or ""
    confidence: np.ndarray  # best candidate's confidence, eq. 11–14 (0 if none)
    candidate: np.ndarray  # best candidate's node id (matched or not) or ""
    reason: np.ndarray  # why not matched ("" when matched)
    # how far the landmark matched may be from where the walker was: the farthest landmark a
    # nearly as likely association (AMBIGUOUS_LOGODDS) gave the same detection (inf: on another
    # floor; 0: unambiguous or not matched)
    spread: np.ndarray

    @property
    def matched(self) -> np.ndarray:
        return self.node != ""


@dataclass(frozen=True)
class Segments:
    """The walk between matched landmarks, one row per segment (the last one open unless the
    end closed it)."""

    from_node: np.ndarray
    to_node: np.ndarray  # "" for the open last segment
    t0: np.ndarray
    t1: np.ndarray
    missed: np.ndarray  # landmarks with a rule the matched path passed undetected (−1: lost)


@dataclass(frozen=True)
class Start:
    """Where and when the walk starts (:mod:`workstation.pipeline.start`)."""

    node: str
    time: float
    # an inferred start: the distinct starts whose best chains survived (another floor or
    # > 5 m from every better one), best first, each with how much less likely it is
    # (log-likelihood); () when the start was given
    candidates: tuple[tuple[str, float], ...] = ()
    time_how: StartTimeHow = "given"  # how the start time was found (start.HOW)

    @property
    def alternative(self) -> str:
        """The best start elsewhere ("" when there is none or the start was given)."""
        return self.candidates[1][0] if len(self.candidates) > 1 else ""

    @property
    def margin(self) -> float:
        """How much less likely the best start elsewhere is (inf: none; nan: start given)."""
        c = self.candidates
        return float("nan") if not c else c[1][1] if len(c) > 1 else float("inf")


@dataclass(frozen=True)
class End:
    """The landmark the walk ends on (walk_end.py; "" when the end stays open), how much likelier
    it is than any landmark elsewhere (log-likelihood; nan: not tried), the farthest landmark
    nearly as likely (as :attr:`Detections.spread`), σ (m) of the dead-reckoned end it was
    matched with, and how the end was taken."""

    node: str = ""
    margin: float = float("nan")
    spread: float = 0.0
    sigma: float = float("nan")
    how: EndHow = "off"  # walk_end.HOW says each in words


@dataclass(frozen=True)
class Track:
    """The corrected trajectory and what the tracker decided: its steps, detections and
    segments, its start and end, and what a building's map changed."""

    steps: Steps
    detections: Detections
    segments: Segments
    start: Start
    end: End = End()
    floor_gaps_hpa: dict[str, float] = field(default_factory=dict)  # {"f0→f1": hPa} at the end
    # what a radio map of the building's other walks changed in the chain chosen (map_prior.py)
    map_rerank: Reranked = Reranked()
    # how the same map turned and scaled a walk that matched nothing (open_by_map.py)
    open_fit: OpenFit = OpenFit()

    def position_at(
        self, t: Times, corrected: bool = False
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x, y, floor at times ``t`` (linear between steps, eq. 19–20)."""
        s = self.steps
        x, y = (s.x_bc, s.y_bc) if corrected else (s.x, s.y)
        return sample_path(s.t, x, y, s.floor, t)


def pressure_at(pressure: Scalar | None, t: Times) -> np.ndarray:
    if pressure is None or len(pressure) == 0:
        return np.zeros(np.size(t))
    return np.interp(t, pressure.t, pressure.value)


class Match(NamedTuple):
    k: int  # detection index (-1 for the start)
    node: str
    route: Route | None  # None: the start, or a relocalization (no route)
    confidence: float  # eq. 11–14


@dataclass(frozen=True)
class TrackerState:
    """Where the tracker stands: the last matched landmark (the anchor) and what it has learnt."""

    node: str
    ax: float
    ay: float
    a_idx: int  # first step after the anchor
    a_t: float
    floors: FloorModel
    length: float  # step length (eq. 10)
    length_var: float  # its variance (m²): how much it may still move (:func:`fuse_step_length`)
    offset: float  # gyro heading offset
    score: float = 0.0
    matches: tuple[Match, ...] = ()


@dataclass(frozen=True)
class WalkToDetection:
    """The steps from the anchor to a detection, walked with the state's model (eq. 7–8)."""

    i_end: int
    px: np.ndarray | None  # per step (only when asked for: the replay)
    py: np.ndarray | None
    theta: np.ndarray | None
    ex: float
    ey: float
    d_star: float
    th_star: float
    p_now: float  # pressure at the detection


def anchor_spread(track: Track) -> tuple[np.ndarray, np.ndarray]:
    """Per segment, the spread (m) of the landmark it starts from and of the one it ends on
    (0 for the start landmark, which is given or quarantined when ambiguous, and for the open
    end). Segments follow the matched detections in order."""
    n = track.segments.t0.size
    s0, s1 = np.zeros(n), np.zeros(n)
    if n == 0:
        return s0, s1
    spread = track.detections.spread[track.detections.matched]
    k = min(spread.size, n - 1)
    s1[:k] = spread[:k]
    s0[1 : k + 1] = spread[:k]
    end = track.end
    if end.node:
        s1[n - 1] = end.spread
        if end.how == "closed" and end.sigma > END_CHECK_M:
            # closed on a landmark only as loosely as its dead-reckoned end was placed: the end
            # anchors the bend no better than that (an end 12 m loose is no 0.5-m landmark)
            s1[n - 1] = max(end.spread, end.sigma)
    return s0, s1
