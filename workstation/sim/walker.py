"""The walker: follows a route over the landmark graph and yields a motion timeline.

The timeline is a set of knots (time → position, altitude, step phase, step amplitude,
heading) that the sensor models sample at their own rates. Step k happens at integer phase k.
Behaviour: natural step-to-step variation; stops at closed doors; smooth turns at corners;
slower steps on stairs with the altitude rising; standing still in the elevator while it moves.
Disturbances (the ``varied`` walk): varying speed, false walking (standing while using the
phone), extra stops and turns in mid-corridor.

The ``realistic`` styles (:func:`realistic`) add what real walks show (issue #12's table, measured
by :mod:`.realism`): a long stand at the start, a tap at every landmark and a few long waits,
a cadence that drifts (slow AR(1)) on top of step-to-step jitter, step lengths that vary, step
amplitudes that vary a lot, corner turns of varied rate with an overshoot the walker corrects over
a few seconds, and the phone swaying in yaw with the stride.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .building import Building


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


@dataclass(frozen=True)
class Motion:
    """Knots of the walk; sample with :meth:`at`. ``events`` lists (t, kind, detail)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    alt: np.ndarray  # floors, continuous (0.5 = half-way up the stair)
    phase: np.ndarray  # steps taken (float)
    amp: np.ndarray  # step acceleration amplitude (0 when still)
    heading: np.ndarray  # direction of travel, unwrapped (rad, CCW from +x)
    landmark_passes: tuple[tuple[float, str], ...]
    false_walking: tuple[tuple[float, float], ...]  # intervals of phone use while standing
    mid_turns: tuple[tuple[float, float], ...]  # (start time, signed angle) look-aside turns
    step_times: np.ndarray  # true heel-strike times
    events: tuple[tuple[float, str, str], ...] = field(default=())
    yaw_error: tuple[tuple[float, float], ...] = ()  # (time, angle): corner overshoot, decays
    sway_rad: float = 0.0  # phone yaw swing with the stride
    taps: tuple[float, ...] = ()  # times the walker taps the phone (at landmarks)

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def at(self, t: np.ndarray) -> dict[str, np.ndarray]:
        """Everything at times ``t``; ``yaw`` includes look-aside turns (the phone's heading)."""
        out = {
            k: np.interp(t, self.t, getattr(self, k))
            for k in ("x", "y", "alt", "phase", "amp", "heading")
        }
        yaw = out["heading"].copy()
        for t0, ang in self.mid_turns:
            # turn over 0.6 s, hold 1.0 s, turn back over 0.6 s
            yaw += ang * np.interp(
                t, [t0, t0 + 0.6, t0 + 1.6, t0 + 2.2], [0, 1, 1, 0], left=0, right=0
            )
        for t0, ang in self.yaw_error:  # reached in ~0.3 s, corrected over a few (τ = 2.5 s)
            dt = np.clip(t - t0, 0, None)
            yaw += ang * (1 - np.exp(-dt / 0.15)) * np.exp(-dt / 2.5)
        if self.sway_rad:
            pos = self.amp[self.amp > 0]
            rel = np.clip(out["amp"] / (float(np.median(pos)) if pos.size else 1.0), 0, 1.5)
            yaw += self.sway_rad * rel * np.sin(np.pi * out["phase"])
        out["yaw"] = yaw
        out["walking"] = (out["amp"] > 1e-6).astype(np.float64)
        out["floor"] = np.round(out["alt"])
        return out


class _Knots:
    def __init__(self):
        self.rows: list[np.ndarray] = []  # columns: t x y alt phase amp heading

    def add(self, t, x, y, alt, phase, amp, heading):
        cols = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(v, float)) for v in (t, x, y, alt, phase, amp, heading))
        )
        self.rows.append(np.column_stack(cols))

    @property
    def last(self) -> np.ndarray:
        return self.rows[-1][-1]


def walk(
    building: Building, route: tuple[str, ...], style: WalkStyle, rng: np.random.Generator
) -> Motion:
    """Simulate walking ``route`` (node ids) in ``building``."""
    g = building.graph
    pts = np.array([[g.node(i).x, g.node(i).y, g.node(i).floor] for i in route])
    legs = list(zip(range(len(route) - 1), range(1, len(route))))
    headings = []
    for a, b in legs:
        d = pts[b, :2] - pts[a, :2]
        headings.append(np.arctan2(d[1], d[0]) if np.hypot(*d) > 1e-6 else np.nan)
    # elevator legs have no direction: the walker turns round inside to face the next leg
    for i in range(len(headings)):
        if np.isnan(headings[i]):
            headings[i] = headings[i - 1] if i else 0.0

    # disturbances on long flat legs, at random fractions
    flat_long = [
        i
        for i, (a, b) in enumerate(legs)
        if pts[a, 2] == pts[b, 2] and np.hypot(*(pts[b, :2] - pts[a, :2])) > 12
    ]
    pauses: dict[int, list[tuple[float, str, float]]] = {}
    turns: dict[int, list[float]] = {}
    for kind, n, span in (
        ("false_walking", style.false_walking, (4.0, 8.0)),
        ("stop", style.extra_stops, (2.0, 5.0)),
    ):
        for leg in rng.choice(flat_long, size=min(n, len(flat_long)), replace=False) if n else []:
            pauses.setdefault(int(leg), []).append(
                (float(rng.uniform(0.3, 0.7)), kind, float(rng.uniform(*span)))
            )
    for leg in (
        rng.choice(flat_long, size=min(style.mid_turns, len(flat_long)), replace=False)
        if style.mid_turns
        else []
    ):
        turns.setdefault(int(leg), []).append(float(rng.uniform(0.25, 0.75)))

    k = _Knots()
    h0 = headings[0]
    t_start = style.start_still_s
    if style.start_still_max_s > style.start_still_s:
        t_start = float(rng.uniform(style.start_still_s, style.start_still_max_s))
    k.add([0.0, t_start], pts[0, 0], pts[0, 1], pts[0, 2], 0.0, 0.0, h0)
    passes = [(t_start, route[0])]
    fw, mt, events, taps, yaw_err = [], [], [], [t_start - 1.0], []
    waits = set()
    if style.waits:
        inner = [i for i in range(1, len(route) - 1) if route[i] not in building.doors]
        waits = set(rng.choice(inner, size=min(style.waits, len(inner)), replace=False).tolist())
    cadence = 0.0
    step_times = []
    heading_unwrapped = h0
    speed_state = style.step_hz
    for li, (a, b) in enumerate(legs):
        t, x, y, alt, phase, _, _ = k.last
        h = heading_unwrapped + _wrap(headings[li] - heading_unwrapped)
        pa, pb = pts[a], pts[b]
        length = float(np.hypot(*(pb[:2] - pa[:2])))
        if (route[a], route[b]) in building.elevators:
            # wait, turn to face the way out, wait, ride, wait
            h_next = headings[li + 1] if li + 1 < len(headings) else h
            h_out = h + _wrap(h_next - h) if abs(_wrap(h_next - h)) < np.pi - 1e-3 else h + np.pi
            ride = float(rng.uniform(6.0, 8.0))
            ts = t + np.cumsum([0.15, 2.0, 1.5, 1.0, ride, 1.5])
            prof = 0.5 - 0.5 * np.cos(np.linspace(0, np.pi, 9))
            k.add(ts[:2], x, y, alt, phase, 0.0, h)
            k.add(ts[2:4], x, y, alt, phase, 0.0, h_out)
            k.add(
                ts[3] + (ts[4] - ts[3]) * np.linspace(0, 1, 9)[1:],
                x,
                y,
                pa[2] + (pb[2] - pa[2]) * prof[1:],
                phase,
                0.0,
                h_out,
            )
            k.add(ts[5], x, y, pb[2], phase, 0.0, h_out)
            events.append((float(ts[3]), "elevator", f"{route[a]}->{route[b]}"))
            heading_unwrapped = h_out
            passes.append((float(ts[5]), route[b]))
            continue
        stair = pa[2] != pb[2]
        if stair:
            hz, step_len, amp = style.stair_step_hz, style.stair_step_len_m, style.amp * 1.2
        else:
            hz, step_len, amp = style.step_hz, style.step_len_m, style.amp
            if style.varying_speed:
                speed_state = float(np.clip(speed_state + rng.normal(0, 0.25), 1.45, 2.35))
                hz = speed_state
                step_len = 0.40 + 0.15 * hz  # faster cadence, longer steps
        n = max(1, int(round(length / step_len)))
        periods = (1.0 / hz) * (1.0 + style.step_jitter * rng.standard_normal(n))
        if style.cadence_sd:  # slow drift of the cadence, carried from leg to leg
            rho = 0.9
            slow = np.empty(n)
            for i in range(n):
                cadence = rho * cadence + np.sqrt(1 - rho**2) * style.cadence_sd * rng.normal()
                slow[i] = cadence
            periods *= np.exp(slow)
        if style.varying_speed and not stair:
            periods *= 1.0 + 0.12 * np.sin(
                np.linspace(0, rng.uniform(1, 3) * np.pi, n) + rng.uniform(0, 6)
            )
        periods = np.clip(periods, 0.3, 1.2)
        if style.step_len_jitter:
            lens = np.clip(1.0 + style.step_len_jitter * rng.standard_normal(n), 0.5, 1.5)
            frac = np.cumsum(lens) / lens.sum()
        else:
            frac = np.arange(1, n + 1) / n
        # pauses split the leg
        leg_pauses = sorted(pauses.get(li, []))
        pause_at = (
            {int(np.clip(round(f * n), 1, n - 1)): (kind, dur) for f, kind, dur in leg_pauses}
            if n > 2
            else {}
        )
        tt = t + np.cumsum(periods)
        shift = 0.0
        for i in range(n):
            tt[i] += shift
            if i + 1 in pause_at:
                kind, dur = pause_at[i + 1]
                shift += dur
        # knots: each step end; plus still knots for the pauses
        z = rng.standard_normal(n)
        j = style.amp_jitter
        amps = amp * (np.exp(j * z - j * j / 2) if style.realistic else 1.0 + j * z)
        cur_t = t
        for i in range(n):
            xi = pa[0] + (pb[0] - pa[0]) * frac[i]
            yi = pa[1] + (pb[1] - pa[1]) * frac[i]
            ai = pa[2] + (pb[2] - pa[2]) * frac[i]
            t_end = tt[i] if (i not in pause_at) else tt[i]
            k.add(t_end, xi, yi, ai, phase + i + 1, amps[i], h)
            step_times.append(t_end)
            cur_t = t_end
            if i + 1 in pause_at:
                kind, dur = pause_at[i + 1]
                k.add([cur_t + 0.15, cur_t + dur - 0.15], xi, yi, ai, phase + i + 1, 0.0, h)
                if kind == "false_walking":
                    fw.append((cur_t + 0.3, cur_t + dur - 0.3))
                events.append((float(cur_t), kind, f"{route[a]}->{route[b]}"))
        # corner turn: heading changes over ±0.35 s around the node (handled by the next leg's
        # first knot); store the turn start on this leg for look-aside turns
        for f in turns.get(li, []):
            tf = float(np.interp(f, np.concatenate([[0], frac]), np.concatenate([[t], tt])))
            ang = float(rng.choice([-1, 1]) * rng.uniform(np.pi / 3, np.pi / 2))
            mt.append((tf, ang))
            events.append((tf, "mid_turn", f"{route[a]}->{route[b]}"))
        heading_unwrapped = h
        passes.append((float(cur_t), route[b]))
        dur = 0.0
        if route[b] in building.doors:
            dur = float(rng.uniform(*style.door_still_s))
            events.append((float(cur_t), "door", route[b]))
        elif b in waits:
            dur = float(rng.uniform(*style.wait_s))
            events.append((float(cur_t), "wait", route[b]))
        elif style.landmark_tap_s and b < len(route) - 1 and rng.random() < style.tap_prob:
            dur = float(rng.uniform(*style.landmark_tap_s))
            events.append((float(cur_t), "tap", route[b]))
        if dur:
            k.add([cur_t + 0.15, cur_t + dur - 0.15], pb[0], pb[1], pb[2], phase + n, 0.0, h)
            if style.landmark_tap_s:
                taps.append(float(cur_t) + min(0.5, dur / 3))
        if style.turn_overshoot_deg and li + 1 < len(headings):
            turn = _wrap(headings[li + 1] - h)
            if np.radians(30) < abs(turn) < np.radians(150):
                err = float(np.radians(style.turn_overshoot_deg) * rng.standard_normal())
                yaw_err.append((float(cur_t) + dur + 0.3, err))

    t, x, y, alt, phase, _, h = k.last
    k.add([t + 0.15, t + style.end_still_s], x, y, alt, phase, 0.0, h)
    arr = np.concatenate(k.rows)
    rate = None
    if style.turn_rate[0] > 0:
        mu, sd = style.turn_rate

        def rate(n):
            return np.clip(rng.normal(mu, sd, n), 1.2, 6.0)

    split = (lambda n: rng.random(n) < style.split_turns) if style.split_turns else None
    arr = _smooth_turns(arr, rate=rate, split=split)
    return Motion(
        t=arr[:, 0],
        x=arr[:, 1],
        y=arr[:, 2],
        alt=arr[:, 3],
        phase=arr[:, 4],
        amp=arr[:, 5],
        heading=arr[:, 6],
        landmark_passes=tuple(passes),
        false_walking=tuple(fw),
        mid_turns=tuple(mt),
        step_times=np.asarray(step_times),
        events=tuple(sorted(events)),
        yaw_error=tuple(yaw_err),
        sway_rad=float(np.radians(style.yaw_sway_deg)),
        taps=tuple(taps) if style.landmark_tap_s else (),
    )


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _smooth_turns(arr: np.ndarray, half: float = 0.35, rate=None, split=None) -> np.ndarray:
    """Replace each heading jump between knots by a linear turn over ±``half`` seconds, or at
    ``rate(n)`` rad/s (drawn per turn) when given; ``split(n)`` marks corners (45°–150°) turned
    in two stages (60 % then 40 %, 1.2 s apart)."""
    t, h = arr[:, 0], arr[:, 6]
    jumps = np.flatnonzero(np.abs(np.diff(h)) > 1e-9)
    if not jumps.size:
        return arr
    # heading as a function of time: piecewise constant with ramps centred at the jump
    tj = 0.5 * (t[jumps] + t[jumps + 1])
    dh = np.diff(h)[jumps]
    if split is not None:
        two = split(dh.size) & (np.abs(dh) > np.radians(45)) & (np.abs(dh) < np.radians(150))
        tj = np.concatenate([tj[~two], tj[two] - 0.5, tj[two] + 0.7])
        dh = np.concatenate([dh[~two], 0.6 * dh[two], 0.4 * dh[two]])
    if rate is not None:
        half = np.clip(np.abs(dh) / (2 * rate(dh.size)), 0.12, 1.5)
    base = h[0]
    ramp = np.clip((t[:, None] - (tj[None, :] - half)) / (2 * half), 0, 1)
    out = arr.copy()
    out[:, 6] = base + (ramp * dh[None, :]).sum(axis=1)
    # add knots at the ramp ends so that interpolation keeps the ramps
    extra_t = np.concatenate([tj - half, tj + half])
    extra_t = extra_t[(extra_t > t[0]) & (extra_t < t[-1])]
    cols = [np.interp(extra_t, t, arr[:, c]) for c in range(arr.shape[1])]
    extra = np.column_stack(cols)
    extra[:, 0] = extra_t
    ramp_e = np.clip((extra_t[:, None] - (tj[None, :] - half)) / (2 * half), 0, 1)
    extra[:, 6] = base + (ramp_e * dh[None, :]).sum(axis=1)
    both = np.concatenate([out, extra])
    order = np.argsort(both[:, 0], kind="stable")
    both = both[order]
    keep = np.concatenate([[True], np.diff(both[:, 0]) > 1e-9])
    return both[keep]
