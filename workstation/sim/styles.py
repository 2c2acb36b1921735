"""How the simulated walker walks: its styles (the named walks' pace, disturbances and, in the
``realistic`` model, what real walks show — issue #12's table, measured by :mod:`.realism`)."""

from __future__ import annotations

from dataclasses import dataclass, replace


@dataclass(frozen=True)
class WalkStyle:
    step_hz: float = 1.85  # mean step frequency
    step_jitter: float = 0.025  # relative std of step-to-step period variation
    step_len_m: float = 0.68
    amp: float = 2.2  # vertical acceleration amplitude while walking (m/s²)
    stair_step_hz: float = 1.6
    stair_step_len_m: float = 0.30  # horizontal
    door_still_s: tuple[float, float] = (1.5, 5.0)
    start_still_s: float = 8.0
    end_still_s: float = 3.0
    varying_speed: bool = False
    false_walking: int = 0  # episodes of standing still while using the phone
    extra_stops: int = 0
    mid_turns: int = 0
    # --- realism (0 / None: the ideal walker) ---
    realistic: bool = False
    start_still_max_s: float = 0.0  # the stand at the start is drawn in [start_still_s, this]
    cadence_sd: float = 0.0  # slow relative variation of the step period (AR(1), ~10 steps)
    step_len_jitter: float = 0.0  # relative std of each step's length
    amp_jitter: float = 0.08  # relative std of each step's amplitude (log-normal)
    landmark_tap_s: tuple[float, float] | None = None  # a stop of this length at every landmark
    tap_prob: float = 1.0  # share of the landmarks where the walker taps
    waits: int = 0  # long waits at random landmarks
    wait_s: tuple[float, float] = (15.0, 40.0)
    turn_rate: tuple[float, float] = (0.0, 0.0)  # corner turn rate mean, sd (rad/s); 0: 0.7 s
    turn_overshoot_deg: float = 0.0  # σ of the phone's heading error after a corner
    split_turns: float = 0.0  # share of corners turned in two stages ~1.2 s apart
    yaw_sway_deg: float = 0.0  # phone yaw swing with the stride (amplitude)


STYLES = {
    "normal": WalkStyle(),
    "heldout": WalkStyle(step_hz=1.95, step_len_m=0.72),
    "varied": WalkStyle(
        varying_speed=True, false_walking=4, extra_stops=3, mid_turns=3, step_jitter=0.05
    ),
}


def realistic(style: WalkStyle) -> WalkStyle:
    """The same walk as real walkers walk it (module doc); values from the real walks' ranges."""
    return replace(
        style,
        realistic=True,
        start_still_s=20.0,
        start_still_max_s=35.0,
        step_jitter=max(style.step_jitter, 0.12),
        cadence_sd=0.04,
        step_len_jitter=0.085,
        amp_jitter=0.7,
        landmark_tap_s=(1.5, 4.0),
        tap_prob=0.2,
        split_turns=0.4,
        waits=3,
        wait_s=(18.0, 35.0),
        turn_rate=(3.6, 1.5),
        turn_overshoot_deg=25.0,
        yaw_sway_deg=2.5,
        end_still_s=5.0,
    )
