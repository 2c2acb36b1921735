"""The parameter groups of Table I and ``Params``, all of them (the package doc)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Literal, get_args

from workstation.errors import ParameterError
from workstation.io.atomic import atomic_write_text
from workstation.io.yamlio import dump_yaml, load_yaml
from workstation.params.schema import COMPASS_HEADING as COMPASS_HEADING
from workstation.params.schema import GYRO_HEADING, HeadingSource, P, _Group
from workstation.rules import BARO, STOP, TURN
from workstation.vocabularies import MetricName, Representation, Weights

# the closed vocabularies of the parameters (each field's choices are these, checked by mypy)
Association = Literal["hmm", "greedy"]
Acceptance = Literal["sigma", "belief"]


@dataclass(frozen=True)
class StepParams(_Group):
    SECTION = "steps"
    variance_window: int = P(
        50, 5, 500, "window for the acceleration variance (motion state)", "samples", "Window size"
    )
    variance_threshold: float = P(
        0.5, 0.01, 20.0, "a peak is a step if the variance exceeds this", "(m/s²)²", "0.5 rule"
    )
    lowpass_hz: float = P(
        3.0, 0.5, 10.0, "low-pass on the acceleration magnitude before peak picking", "Hz"
    )
    min_period_s: float = P(
        0.4, 0.1, 1.0, "minimum time between two steps (the paper's T_min: 2.5 steps a second)", "s"
    )
    min_peak_ms2: float = P(0.4, 0.0, 5.0, "peak must rise this far above gravity", "m/s²")
    still_gap_s: float = P(
        0.3, 0.0, 2.0, "still runs shorter than this inside walking are ignored", "s"
    )


@dataclass(frozen=True)
class HeadingParams(_Group):
    SECTION = "heading"
    gravity_lowpass_hz: float = P(
        0.6, 0.05, 5.0, "low-pass giving gravity (tilt) from the accelerometer", "Hz"
    )


@dataclass(frozen=True)
class AccLandmarkParams(_Group):
    SECTION = STOP
    walking_s: float = P(
        2.0, 0.2, 20.0, "walking before and after the stop (K1)", "s", "Walking state threshold"
    )
    still_min_s: float = P(
        1.0, 0.1, 30.0, "shortest stop (K2 lower bound)", "s", "Still state threshold"
    )
    still_max_s: float = P(
        8.0, 0.5, 60.0, "longest stop (K2 upper bound)", "s", "Still state threshold"
    )


@dataclass(frozen=True)
class GyroLandmarkParams(_Group):
    SECTION = TURN
    window: int = P(10, 1, 200, "moving-mean window on the vertical rate", "samples", "Window size")
    threshold_rad_s: float = P(
        1.1, 0.1, 10.0, "|vertical rate| above this is a turn (ε_gyro)", "rad/s", "Gyro threshold"
    )
    merge_s: float = P(0.8, 0.0, 5.0, "turn detections closer than this are one turn", "s")
    min_angle_deg: float = P(
        0.0, 0.0, 90.0, "turns that change the heading less than this are not landmarks", "°"
    )
    slow_turn_deg: float = P(
        60.0, 0.0, 180.0,
        "a turn whose rate stays under ε_gyro (above ε_gyro/2) still counts when the heading "
        "changes by at least this (0: the paper's rate rule alone)", "°",
    )  # fmt: skip
    wiggle_deg: float = P(
        30.0, 0.0, 90.0,
        "back-and-forth turns in quick succession that net less than this are the phone "
        "swinging in the hand, not landmarks (0: keep them)", "°",
    )  # fmt: skip


@dataclass(frozen=True)
class BaroLandmarkParams(_Group):
    SECTION = BARO
    window_s: float = P(
        1.0, 0.1, 10.0, "pressure window for the means p_i (not given in the paper)", "s"
    )
    horizontal_hpa: float = P(
        0.05, 0.001, 1.0, "|p_i − p_i−1| below this is level walking (ε_baro1)", "hPa", "ε_baro1"
    )
    vertical_hpa: float = P(
        0.2,
        0.01,
        5.0,
        "total change of a monotonic run for a floor change (ε_baro2)",
        "hPa",
        "ε_baro2",
    )
    dead_band_hpa: float = P(
        0.02,
        0.0,
        0.5,
        "window changes smaller than this neither continue nor break a run (0 = the paper's strict sign rule)",
        "hPa",
    )
    max_level_s: float = P(
        6.0, 0.0, 60.0, "a run survives level stretches (landings) up to this long", "s"
    )


@dataclass(frozen=True)
class PDRParams(_Group):
    SECTION = "pdr"
    floor_hpa: float = P(
        0.45, 0.05, 2.0, "pressure difference between floors (p_d)", "hPa", "Pressure difference"
    )
    heading_threshold_deg: float = P(
        30.0, 1.0, 180.0, "heading match for a candidate (ε_θ)", "deg", "Heading threshold"
    )
    confidence_threshold: float = P(
        0.25, 0.0, 100.0, "minimum confidence of a match (ε_v)", "", "Confidence threshold"
    )
    initial_step_length_m: float = P(
        0.63, 0.2, 1.5, "step length before the first calibration", "m", "Initial step length"
    )
    min_step_length_m: float = P(0.35, 0.1, 1.5, "eq. 10 results are clamped to [min, max]", "m")
    max_step_length_m: float = P(1.0, 0.3, 2.0, "eq. 10 results are clamped to [min, max]", "m")
    min_calibration_m: float = P(
        3.0,
        0.0,
        100.0,
        "eq. 10 recalibrates the step length only over paths at least this long (a route back to its own landmark, or a neighbour, says nothing of the distance walked)",
        "m",
    )
    step_length_sd_m: float = P(
        0.08,
        0.0,
        0.5,
        "σ of a walker's step length about the initial one; eq. 10 weighs each path's measurement against it by their uncertainties (0: each calibration replaces the length, as printed)",
        "m",
    )
    max_hops: int = P(
        3,
        1,
        6,
        "candidates: the landmarks met next (1, the paper's successors) or after missing up to max_hops − 1 detectable ones",
        "landmarks",
    )
    min_distance_m: float = P(0.25, 0.01, 5.0, "|d_k − d*| floor in g = 1/|d_k − d*| (eq. 14)", "m")
    relocalize_after_m: float = P(
        40.0,
        5.0,
        1000.0,
        "after walking this far without a match, any landmark with the rule on the floor is a candidate, by its distance from the estimate",
        "m",
    )
    distance_slack: float = P(
        0.0,
        0.0,
        1.0,
        "|d_k − d*| up to this fraction of d_k counts as no error (0 = eq. 14 as printed)",
        "",
    )
    floor_distance_m: float = P(
        4.0,
        0.1,
        50.0,
        "over a floor change, g = 1/(|floor error| × this) replaces the distance term",
        "m",
    )
    association: Association = P(
        "hmm",
        help="hmm: keep the association hypotheses that explain the whole walk best (offline, like HMM map matching); greedy: match each detection as it comes (the paper)",
        choices=get_args(Association),
    )
    beam_width: int = P(16, 1, 256, "association hypotheses kept (hmm)", "")
    step_length_cv: float = P(
        0.10,
        0.0,
        0.5,
        "spread of the distance walked against a path, per metre of path (step length varies ~8-9 % within a leg)",
        "",
    )
    match_gain: float = P(
        3.0,
        0.0,
        20.0,
        "log-odds for explaining a detection by a landmark that fits it exactly (hmm)",
        "",
    )
    miss_cost: float = P(
        1.5,
        0.0,
        20.0,
        "log-odds cost of passing a landmark with rules without a detection (hmm)",
        "",
    )
    relocalize_cost: float = P(
        6.0, 0.0, 50.0, "log-odds cost of a recovery match, off the graph's routes (hmm)", ""
    )
    heading_source: HeadingSource = P(GYRO_HEADING, choices=get_args(HeadingSource),
        help="sensor heading between landmarks (gyro aligned to the graph, or compass)")  # fmt: skip
    snap_heading: bool = P(True, help="use the edge heading while walking along a known edge")
    turn_exits: bool = P(
        False,
        help="score the direction walked after a turn against the landmark's ways out (off: "
        "it raised inferred starts' margins, and wrong starts escaped the quarantine)",
    )
    start_node: str | None = P(None, help="landmark where the walk starts; inferred when empty")
    end_node: str | None = P(
        None,
        help="landmark where the walk ends (the surveyor stopped recording there): its last "
        "stretch is closed on it, and the walk is checked by it when the sensors end within 3σ",
    )
    end_on_landmark: bool = P(
        True,
        help="the surveyor stops recording on a landmark: the walk's end closes its last "
        "segment on the landmark it unambiguously ends at",
    )
    map_weight: float = P(0.5, 0.0, 1.0, "how much a map of the building's other walks counts in "
                          "choosing the chain of matches (0: off; map_prior.py)", "")  # fmt: skip
    map_sigma_m: float = P(8.0, 1.0, 50.0, "how far 1-NN on it puts a scan from its place", "m")
    map_inlier: float = P(0.5, 0.05, 0.95, "the share of scans it puts near (others: anywhere)", "")
    start_walk_s: float = P(1.5, 0.0, 30.0, "the walk starts with the first walking this long", "s")
    start_still_s: float = P(
        4.0, 0.0, 60.0, "unless the phone was handled, then stood this long: start after", "s"
    )
    handling_rate: float = P(
        1.5, 0.3, 10.0, "moving while the phone turns faster than this is handling", "rad/s"
    )
    start_search_s: float = P(
        90.0, 0.0, 600.0, "search for the start landmark widely in the first seconds", "s"
    )


@dataclass(frozen=True)
class BeliefParams(_Group):
    SECTION = "belief"
    t_min_s: float = P(0.4, 0.1, 2.0, "shortest valid step period (T_min)", "s", "T_min")
    t_max_s: float = P(1.0, 0.2, 5.0, "longest valid step period (T_max)", "s", "T_max")
    threshold: float = P(
        15.0,
        0.0,
        1000.0,
        "segments with a belief above this are trusted (ε_S)",
        "",
        "Belief threshold",
    )
    min_period_sd_s: float = P(
        0.005, 0.0, 0.5, "σ(T') is floored here: periods are only known to a sample or so", "s"
    )
    accept_open_segments: bool = P(False, help="trust the last segment, which no landmark closes")
    min_valid_steps: int = P(3, 2, 100, "segments with fewer valid steps get belief 0", "steps")
    landmark_stops_apart: bool = P(
        True,
        help="stops at a segment's two landmarks (and the stand before the walk) are not "
        "step periods of the segment",
    )
    boundary_window_s: float = P(
        3.0, 0.0, 30.0, "a stop this close to a landmark's detection is a stop at the landmark", "s"
    )


@dataclass(frozen=True)
class RadioMapParams(_Group):
    SECTION = "radiomap"
    backward_correction: bool = P(
        True, help="bend each closed segment to end on its landmark before placing scans"
    )
    scans_at_landmark_stops: bool = P(
        True, help="scans taken standing still at a matched landmark are reference points there"
    )
    acceptance: Acceptance = P(
        "sigma",
        help="which scans become reference points: those placed to within max_sigma_m "
        "(sigma), or those of segments whose belief passes eps_S (belief, the paper)",
        choices=get_args(Acceptance),
    )
    max_sigma_m: float = P(
        2.5, 0.1, 20.0, "with acceptance sigma: the largest placement uncertainty kept (σ: the "
        "radius that holds 68 % of the points)", "m")  # fmt: skip
    fill_gaps_m: float = P(
        3.0, 0.0, 50.0,
        "scans of untrusted closed segments farther than this from every trusted one are kept "
        "(0: off, the paper)", "m",
    )  # fmt: skip


@dataclass(frozen=True)
class LocalizeParams(_Group):
    SECTION = "localize"
    tau_dbm: float = P(-90.0, -120.0, -30.0, "RSS below this counts as unheard (positive "
                       "representation)", "dBm", "τ")  # fmt: skip
    metric: MetricName = P("sorensen", help="fingerprint distance (the paper: euclidean; "
                           "matchers.py)", choices=get_args(MetricName))  # fmt: skip
    k: int = P(5, 1, 50, "neighbours averaged (1 = the paper's 1-NN)", "")
    representation: Representation = P("powed", help="fingerprint values: eq. 21's positive "
                                       "ones (the paper) or powed, (v / -min)^e",
                                       choices=get_args(Representation))  # fmt: skip
    weights: Weights = P("inverse-distance", help="how the k neighbours' positions are averaged",
                         choices=get_args(Weights))  # fmt: skip
    align_devices: bool = P(True, help="estimate and remove each walk's (phone's) RSS offset "
                            "against the map")  # fmt: skip


GROUPS = {
    "steps": StepParams,
    "heading": HeadingParams,
    AccLandmarkParams.SECTION: AccLandmarkParams,
    GyroLandmarkParams.SECTION: GyroLandmarkParams,
    BaroLandmarkParams.SECTION: BaroLandmarkParams,
    "pdr": PDRParams,
    "belief": BeliefParams,
    "radiomap": RadioMapParams,
    "localize": LocalizeParams,
}


@dataclass(frozen=True)
class Params:
    steps: StepParams = field(default_factory=StepParams)
    heading: HeadingParams = field(default_factory=HeadingParams)
    acc: AccLandmarkParams = field(default_factory=AccLandmarkParams)
    gyro: GyroLandmarkParams = field(default_factory=GyroLandmarkParams)
    baro: BaroLandmarkParams = field(default_factory=BaroLandmarkParams)
    pdr: PDRParams = field(default_factory=PDRParams)
    belief: BeliefParams = field(default_factory=BeliefParams)
    radiomap: RadioMapParams = field(default_factory=RadioMapParams)
    localize: LocalizeParams = field(default_factory=LocalizeParams)

    def __post_init__(self):
        if self.acc.still_min_s > self.acc.still_max_s:
            raise ParameterError("acc.still_min_s must not exceed acc.still_max_s")
        if self.belief.t_min_s >= self.belief.t_max_s:
            raise ParameterError("belief.t_min_s must be below belief.t_max_s")
        if self.pdr.min_step_length_m > self.pdr.max_step_length_m:
            raise ParameterError("pdr.min_step_length_m must not exceed pdr.max_step_length_m")

    def to_dict(self) -> dict[str, dict[str, Any]]:
        return {name: dataclasses.asdict(getattr(self, name)) for name in GROUPS}

    @classmethod
    def from_dict(cls, data: dict | None) -> Params:
        data = data or {}
        if not isinstance(data, dict):
            raise ParameterError(
                "parameters are a mapping of sections (steps, acc, gyro, baro, pdr, belief, ...)"
            )
        unknown = set(data) - set(GROUPS)
        if unknown:
            raise ParameterError(
                f"unknown section(s): {', '.join(sorted(map(str, unknown)))} (known: {', '.join(GROUPS)})"
            )
        groups = {}
        for name, kind in GROUPS.items():
            sec = data.get(name) or {}
            if not isinstance(sec, dict):
                raise ParameterError(f"{name}: expected a mapping of parameters")
            known = {f.name for f in fields(kind)}
            bad = set(sec) - known
            if bad:
                raise ParameterError(
                    f"{name}: unknown parameter(s) {', '.join(sorted(map(str, bad)))} (known: {', '.join(sorted(known))})"
                )
            groups[name] = kind(**sec)
        return cls(**groups)

    def updated(self, **changes: Any) -> Params:
        """``updated(**{"belief.threshold": 20})`` → a new, validated Params."""
        d = self.to_dict()
        for key, v in changes.items():
            sec, _, name = key.partition(".")
            if sec not in d or name not in d[sec]:
                raise ParameterError(f"unknown parameter {key}")
            d[sec][name] = v
        return Params.from_dict(d)

    def to_yaml(self) -> str:
        return dump_yaml(self.to_dict(), sort_keys=False)

    def save(self, path: str | Path):
        return atomic_write_text(path, self.to_yaml(), backup=True)

    @classmethod
    def load(cls, path: str | Path) -> Params:
        path = Path(path)
        data = load_yaml(path, "parameter file")
        try:
            return cls.from_dict(data)
        except ParameterError as e:
            raise ParameterError(f"{path}: {e}") from None
