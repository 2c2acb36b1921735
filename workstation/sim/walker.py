"""The walker: follows a route over the landmark graph and yields a motion timeline.

The timeline is a set of knots (time → position, altitude, step phase, step amplitude,
heading) that the sensor models sample at their own rates. Step k happens at integer phase k.
Behaviour: natural step-to-step variation; stops at closed doors; smooth turns at corners;
slower steps on stairs with the altitude rising; standing still in the elevator while it moves.
Disturbances (the ``varied`` walk): varying speed, false walking (standing while using the
phone), extra stops and turns in mid-corridor.

The ``realistic`` styles (:func:`.styles.realistic`) add what real walks show (issue #12's table, measured
by :mod:`.realism`): a long stand at the start, a tap at every landmark and a few long waits,
a cadence that drifts (slow AR(1)) on top of step-to-step jitter, step lengths that vary, step
amplitudes that vary a lot, corner turns of varied rate with an overshoot the walker corrects over
a few seconds, and the phone swaying in yaw with the stride.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from workstation.sim.building import Building
from workstation.sim.styles import WalkStyle


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


@dataclass
class _Trace:
    """What the walk records besides its knots, leg after leg (and the cadence and speed
    carried from one leg to the next)."""

    passes: list = field(default_factory=list)  # (t, landmark) as each is reached
    false_walking: list = field(default_factory=list)  # (t0, t1)
    mid_turns: list = field(default_factory=list)  # (t, angle)
    events: list = field(default_factory=list)  # (t, kind, where)
    taps: list = field(default_factory=list)
    yaw_error: list = field(default_factory=list)  # (t, overshoot)
    step_times: list = field(default_factory=list)
    cadence: float = 0.0  # the slow AR(1) drift of log period
    speed: float = 0.0  # step frequency of the varying-speed style
    heading: float = 0.0  # unwrapped heading at the end of the last leg


def walk(
    building: Building, route: tuple[str, ...], style: WalkStyle, rng: np.random.Generator
) -> Motion:
    """Simulate walking ``route`` (node ids) in ``building``: a stand at the start, then leg
    after leg (a lift ride, or steps with their pauses and look-aside turns, then what the
    walker does at the landmark reached), a stand at the end; corners turned smoothly."""
    g = building.graph
    pts = np.array([[g.node(i).x, g.node(i).y, g.node(i).floor] for i in route])
    legs = list(zip(range(len(route) - 1), range(1, len(route))))
    headings = _leg_headings(pts, legs)
    pauses, turns = _disturbances(pts, legs, style, rng)
    k = _Knots()
    t_start = style.start_still_s
    if style.start_still_max_s > style.start_still_s:
        t_start = float(rng.uniform(style.start_still_s, style.start_still_max_s))
    k.add([0.0, t_start], pts[0, 0], pts[0, 1], pts[0, 2], 0.0, 0.0, headings[0])
    tr = _Trace(passes=[(t_start, route[0])], taps=[t_start - 1.0], speed=style.step_hz,
                heading=headings[0])  # fmt: skip
    waits = set()
    if style.waits:
        inner = [i for i in range(1, len(route) - 1) if route[i] not in building.doors]
        waits = set(rng.choice(inner, size=min(style.waits, len(inner)), replace=False).tolist())
    for li, (a, b) in enumerate(legs):
        h = tr.heading + _wrap(headings[li] - tr.heading)
        where = f"{route[a]}->{route[b]}"
        if (route[a], route[b]) in building.elevators:
            h_next = headings[li + 1] if li + 1 < len(headings) else h
            _ride(k, tr, pts[a], pts[b], h, h_next, route[b], where, rng)
            continue
        n, cur_t = _walk_leg(k, tr, pts[a], pts[b], h, style, rng, pauses.get(li, []),
                             turns.get(li, []), where)  # fmt: skip
        tr.heading = h
        tr.passes.append((float(cur_t), route[b]))
        dur = _stand(k, tr, building, route, b, b in waits, style, rng, float(cur_t), pts[b], h)
        if style.turn_overshoot_deg and li + 1 < len(headings):
            turn = _wrap(headings[li + 1] - h)
            if np.radians(30) < abs(turn) < np.radians(150):
                err = float(np.radians(style.turn_overshoot_deg) * rng.standard_normal())
                tr.yaw_error.append((float(cur_t) + dur + 0.3, err))

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
        landmark_passes=tuple(tr.passes),
        false_walking=tuple(tr.false_walking),
        mid_turns=tuple(tr.mid_turns),
        step_times=np.asarray(tr.step_times),
        events=tuple(sorted(tr.events)),
        yaw_error=tuple(tr.yaw_error),
        sway_rad=float(np.radians(style.yaw_sway_deg)),
        taps=tuple(tr.taps) if style.landmark_tap_s else (),
    )


def _stand(k: _Knots, tr: _Trace, building: Building, route: tuple[str, ...], b: int, wait: bool,
           style: WalkStyle, rng: np.random.Generator, cur_t: float, pb: np.ndarray,
           h: float) -> float:  # fmt: skip
    """What the walker does at the landmark ``route[b]`` just reached: stand at a door, wait
    where chosen, or tap the phone (with ``style.tap_prob``) — the stand added to the knots,
    the event to the trace; returns how long (0: walked on)."""
    phase = k.last[4]
    dur = 0.0
    if route[b] in building.doors:
        dur = float(rng.uniform(*style.door_still_s))
        tr.events.append((cur_t, "door", route[b]))
    elif wait:
        dur = float(rng.uniform(*style.wait_s))
        tr.events.append((cur_t, "wait", route[b]))
    elif style.landmark_tap_s and b < len(route) - 1 and rng.random() < style.tap_prob:
        dur = float(rng.uniform(*style.landmark_tap_s))
        tr.events.append((cur_t, "tap", route[b]))
    if dur:
        k.add([cur_t + 0.15, cur_t + dur - 0.15], pb[0], pb[1], pb[2], phase, 0.0, h)
        if style.landmark_tap_s:
            tr.taps.append(cur_t + min(0.5, dur / 3))
    return dur


def _leg_headings(pts: np.ndarray, legs: list[tuple[int, int]]) -> list[float]:
    """The direction of each leg; a lift leg has none: the walker turns round inside to face
    the next leg (the previous leg's heading, or 0 first)."""
    headings = []
    for a, b in legs:
        d = pts[b, :2] - pts[a, :2]
        headings.append(float(np.arctan2(d[1], d[0])) if np.hypot(*d) > 1e-6 else np.nan)
    for i in range(len(headings)):
        if np.isnan(headings[i]):
            headings[i] = headings[i - 1] if i else 0.0
    return headings


def _disturbances(pts, legs, style: WalkStyle, rng):
    """On long flat legs, at random fractions: pauses {leg: [(fraction, kind, seconds)]} (false
    walking, extra stops) and look-aside turns {leg: [fraction]}."""
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
    return pauses, turns


def _ride(k: _Knots, tr: _Trace, pa, pb, h: float, h_next: float, node: str, where: str, rng):
    """A lift leg: wait, turn to face the way out, wait, ride, wait."""
    t, x, y, alt, phase, _, _ = k.last
    h_out = h + _wrap(h_next - h) if abs(_wrap(h_next - h)) < np.pi - 1e-3 else h + np.pi
    ride = float(rng.uniform(6.0, 8.0))
    ts = t + np.cumsum([0.15, 2.0, 1.5, 1.0, ride, 1.5])
    prof = 0.5 - 0.5 * np.cos(np.linspace(0, np.pi, 9))
    k.add(ts[:2], x, y, alt, phase, 0.0, h)
    k.add(ts[2:4], x, y, alt, phase, 0.0, h_out)
    k.add(ts[3] + (ts[4] - ts[3]) * np.linspace(0, 1, 9)[1:], x, y,
          pa[2] + (pb[2] - pa[2]) * prof[1:], phase, 0.0, h_out)  # fmt: skip
    k.add(ts[5], x, y, pb[2], phase, 0.0, h_out)
    tr.events.append((float(ts[3]), "elevator", where))
    tr.heading = h_out
    tr.passes.append((float(ts[5]), node))


def _step_periods(n: int, hz: float, level: bool, style: WalkStyle, tr: _Trace, rng) -> np.ndarray:
    """Seconds per step of a leg: step-to-step jitter, the cadence's slow drift (carried from
    leg to leg) and, in the varying-speed style, a slow swing along a level leg."""
    periods = (1.0 / hz) * (1.0 + style.step_jitter * rng.standard_normal(n))
    if style.cadence_sd:  # slow drift of the cadence, carried from leg to leg
        rho = 0.9
        slow = np.empty(n)
        for i in range(n):
            tr.cadence = rho * tr.cadence + np.sqrt(1 - rho**2) * style.cadence_sd * rng.normal()
            slow[i] = tr.cadence
        periods *= np.exp(slow)
    if style.varying_speed and level:
        periods *= 1.0 + 0.12 * np.sin(
            np.linspace(0, rng.uniform(1, 3) * np.pi, n) + rng.uniform(0, 6)
        )
    return np.clip(periods, 0.3, 1.2)


def _walk_leg(k: _Knots, tr: _Trace, pa, pb, h: float, style: WalkStyle, rng, leg_pauses,
              leg_turns, where: str) -> tuple[int, float]:  # fmt: skip
    """The steps of a level or stair leg, with the leg's pauses and look-aside turns: knots at
    each step's end. Returns the number of steps and the time the landmark is reached."""
    t, _, _, _, phase, _, _ = k.last
    length = float(np.hypot(*(pb[:2] - pa[:2])))
    stair = pa[2] != pb[2]
    if stair:
        hz, step_len, amp = style.stair_step_hz, style.stair_step_len_m, style.amp * 1.2
    else:
        hz, step_len, amp = style.step_hz, style.step_len_m, style.amp
        if style.varying_speed:
            tr.speed = float(np.clip(tr.speed + rng.normal(0, 0.25), 1.45, 2.35))
            hz = tr.speed
            step_len = 0.40 + 0.15 * hz  # faster cadence, longer steps
    n = max(1, int(round(length / step_len)))
    periods = _step_periods(n, hz, not stair, style, tr, rng)
    if style.step_len_jitter:
        lens = np.clip(1.0 + style.step_len_jitter * rng.standard_normal(n), 0.5, 1.5)
        frac = np.cumsum(lens) / lens.sum()
    else:
        frac = np.arange(1, n + 1) / n
    # pauses split the leg
    pause_at = (
        {int(np.clip(round(f * n), 1, n - 1)): (kind, dur) for f, kind, dur in sorted(leg_pauses)}
        if n > 2
        else {}
    )
    tt = t + np.cumsum(periods)
    shift = 0.0
    for i in range(n):
        tt[i] += shift
        if i + 1 in pause_at:
            shift += pause_at[i + 1][1]
    # knots: each step end; plus still knots for the pauses
    z = rng.standard_normal(n)
    j = style.amp_jitter
    amps = amp * (np.exp(j * z - j * j / 2) if style.realistic else 1.0 + j * z)
    cur_t = t
    for i in range(n):
        xi = pa[0] + (pb[0] - pa[0]) * frac[i]
        yi = pa[1] + (pb[1] - pa[1]) * frac[i]
        ai = pa[2] + (pb[2] - pa[2]) * frac[i]
        k.add(tt[i], xi, yi, ai, phase + i + 1, amps[i], h)
        tr.step_times.append(tt[i])
        cur_t = tt[i]
        if i + 1 in pause_at:
            kind, dur = pause_at[i + 1]
            k.add([cur_t + 0.15, cur_t + dur - 0.15], xi, yi, ai, phase + i + 1, 0.0, h)
            if kind == "false_walking":
                tr.false_walking.append((cur_t + 0.3, cur_t + dur - 0.3))
            tr.events.append((float(cur_t), kind, where))
    # a look-aside turn in mid-corridor (the corner turns are smoothed from the knots)
    for f in leg_turns:
        tf = float(np.interp(f, np.concatenate([[0], frac]), np.concatenate([[t], tt])))
        ang = float(rng.choice([-1, 1]) * rng.uniform(np.pi / 3, np.pi / 2))
        tr.mid_turns.append((tf, ang))
        tr.events.append((tf, "mid_turn", where))
    return n, cur_t


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
