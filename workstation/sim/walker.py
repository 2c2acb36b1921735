"""The walker: follows a route over the landmark graph and yields a motion timeline.

The timeline is a set of knots (time → position, altitude, step phase, step amplitude,
heading) that the sensor models sample at their own rates. Step k happens at integer phase k.
Behaviour: natural step-to-step variation; stops at closed doors; smooth turns at corners;
slower steps on stairs with the altitude rising; standing still in the elevator while it moves.
Disturbances (the ``varied`` walk): varying speed, false walking (standing while using the
phone), extra stops and turns in mid-corridor.
"""

from __future__ import annotations

from dataclasses import dataclass, field

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


STYLES = {
    "normal": WalkStyle(),
    "heldout": WalkStyle(step_hz=1.95, step_len_m=0.72),
    "varied": WalkStyle(
        varying_speed=True, false_walking=4, extra_stops=3, mid_turns=3, step_jitter=0.05
    ),
}


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
    for kind, n, dur in (
        ("false_walking", style.false_walking, (4.0, 8.0)),
        ("stop", style.extra_stops, (2.0, 5.0)),
    ):
        for leg in rng.choice(flat_long, size=min(n, len(flat_long)), replace=False) if n else []:
            pauses.setdefault(int(leg), []).append(
                (float(rng.uniform(0.3, 0.7)), kind, float(rng.uniform(*dur)))
            )
    for leg in (
        rng.choice(flat_long, size=min(style.mid_turns, len(flat_long)), replace=False)
        if style.mid_turns
        else []
    ):
        turns.setdefault(int(leg), []).append(float(rng.uniform(0.25, 0.75)))

    k = _Knots()
    h0 = headings[0]
    k.add([0.0, style.start_still_s], pts[0, 0], pts[0, 1], pts[0, 2], 0.0, 0.0, h0)
    passes = [(style.start_still_s, route[0])]
    fw, mt, events = [], [], []
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
        if style.varying_speed and not stair:
            periods *= 1.0 + 0.12 * np.sin(
                np.linspace(0, rng.uniform(1, 3) * np.pi, n) + rng.uniform(0, 6)
            )
        periods = np.clip(periods, 0.3, 1.2)
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
        amps = amp * (1.0 + 0.08 * rng.standard_normal(n))
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
        if route[b] in building.doors:
            dur = float(rng.uniform(*style.door_still_s))
            k.add([cur_t + 0.15, cur_t + dur - 0.15], pb[0], pb[1], pb[2], phase + n, 0.0, h)
            events.append((float(cur_t), "door", route[b]))
    t, x, y, alt, phase, _, h = k.last
    k.add([t + 0.15, t + style.end_still_s], x, y, alt, phase, 0.0, h)
    arr = np.concatenate(k.rows)
    arr = _smooth_turns(arr)
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
    )


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _smooth_turns(arr: np.ndarray, half: float = 0.35) -> np.ndarray:
    """Replace each heading jump between knots by a linear turn over ±``half`` seconds."""
    t, h = arr[:, 0], arr[:, 6]
    jumps = np.flatnonzero(np.abs(np.diff(h)) > 1e-9)
    if not jumps.size:
        return arr
    # heading as a function of time: piecewise constant with ramps centred at the jump
    tj = 0.5 * (t[jumps] + t[jumps + 1])
    dh = np.diff(h)[jumps]
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
