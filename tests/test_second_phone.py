"""Two walks of two phones joined with every clock re-timed, seen by the phones' hardware (issue
#67 item 2; session/clocks.py ``resolution_change``): a magnetometer reports whole steps of its
resolution, so every change between two of its samples is a whole number of steps. Where the
changes leave that grid for another, another phone's sensor begins. The museum's two phones
read 0.06 and 0.1 µT; its walks keep one grid from first to last sample, through the phones' own
re-calibrations; a stream of floats on no grid (the mall's) says nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import IPIN, need
from tests.test_two_clocks import quarantined_then_split_clean
from workstation.session import load_session
from workstation.session.clocks import GRID_BLOCK, resolution_change, step_of
from workstation.session.split import inertial_start

#: GetSensorData records whose third field is the sensor's own timestamp
SENSOR_CLOCK = ("ACCE", "GYRO", "MAGN", "PRES", "LIGH", "PROX", "HUMI", "TEMP", "AHRS", "GNSS",
                "WIFI")  # fmt: skip
#: museum walks by phone (SM-A520F: 0.06 µT; SM-G930F: 0.1 µT) that the barometer lets join
A520F = ("03_repetition01", "04_repetition01")
G930F = "03_repetition03"


def _records(path: Path) -> tuple[list[str], list[list[str]]]:
    head, rows = [], []
    for ln in path.read_text(encoding="utf-8", errors="replace").splitlines():
        f = ln.split(";")
        if len(f) > 2 and f[0].isupper() and f[0].isalnum():
            try:
                float(f[1])
            except ValueError:
                head.append(ln)
                continue
            rows.append(f)
        else:
            head.append(ln)
    return head, rows


def _offsets(rows: list[list[str]]) -> dict[str, float]:
    """Each sensor's median app-minus-sensor time (s)."""
    out: dict[str, list[float]] = {}
    for f in rows:
        if f[0] in SENSOR_CLOCK:
            try:
                out.setdefault(f[0], []).append(float(f[1]) - float(f[2]))
            except ValueError:
                pass
    return {k: float(np.median(v)) for k, v in out.items()}


def join_gsd(a: Path, b: Path, out: Path) -> float:
    """Logfile ``b`` joined after ``a`` with both clocks re-timed (each sensor's clock moved to
    keep ``a``'s offset to the app's); where ``b`` begins (s, on the joined walk's inertial
    clock)."""
    head, ra = _records(a)
    _, rb = _records(b)
    d = max(float(f[1]) for f in ra) + 0.01 - min(float(f[1]) for f in rb)
    oa, ob = _offsets(ra), _offsets(rb)
    moved = []
    for f in rb:
        g = list(f)
        g[1] = f"{float(f[1]) + d:.3f}"
        if f[0] in SENSOR_CLOCK and f[0] in oa:
            try:
                g[2] = f"{float(f[2]) + d + ob.get(f[0], 0.0) - oa[f[0]]:.4f}"
            except ValueError:
                pass
        moved.append(g)
    out.write_text("\n".join(head + [";".join(f) for f in ra + moved]) + "\n", encoding="utf-8")
    first = load_session(a)
    return max(first.accelerometer.t[-1], first.gyroscope.t[-1]) - inertial_start(first) + 0.01


def _sensor(rng, n: int, step: float) -> np.ndarray:
    """A magnetometer of resolution ``step`` at 50 Hz: whole steps of a field wandering by ~1 µT a
    sample as a walker turns, less a hard-iron bias (not a whole number of steps)."""
    counts = np.cumsum(np.round(rng.normal(0, 1.0 / step, (n, 3))), axis=0)
    return counts * step - rng.normal([-30, 10, 40], 5)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("steps", [(0.06, 0.1), (0.1, 0.06), (0.06, 0.12), (0.3, 0.15)])
def test_another_resolution_is_another_phone_found_where_it_begins(seed, steps):
    rng = np.random.default_rng(seed)
    n, k = 3000, int(rng.integers(800, 2200))
    t = np.arange(n) * 0.02
    a, b = _sensor(rng, n, steps[0]), _sensor(rng, n, steps[1])
    assert step_of(a) == pytest.approx(steps[0]) and resolution_change(t, a) is None
    found = resolution_change(t, np.vstack([a[:k], b[k:]]))
    assert found is not None and found[0] == pytest.approx(t[k])
    assert f"from {steps[0]:.3g} to {steps[1]:.3g} µT" in found[1]


@pytest.mark.parametrize("seed", range(3))
def test_one_sensor_re_calibrated_glitching_or_on_no_grid_is_no_second_phone(seed):
    rng = np.random.default_rng(seed)
    n = 3000
    t = np.arange(n) * 0.02
    v = _sensor(rng, n, 0.06)
    v[1500:] += np.array([3.217, -1.05, 0.4])  # the phone re-estimates its bias mid-walk
    bad = rng.choice(n, 10, replace=False)
    v[bad] += rng.normal(0, 5, (10, 3))  # ten garbled samples
    v[2000 : 2000 + GRID_BLOCK // 2] = v[2000]  # the phone lying still a second
    assert resolution_change(t, v) is None
    floats = np.cumsum(rng.normal(0, 1.0, (n, 3)), axis=0)  # a filtered stream: no grid
    assert step_of(floats) is None and resolution_change(t, floats) is None
    assert resolution_change(t[:100], v[:100]) is None  # too short to say


@pytest.mark.shared_data
@pytest.mark.parametrize("pair", [(G930F, A520F[1]), (A520F[1], G930F)])
def test_two_museum_walks_of_two_phones_joined_with_every_clock_re_timed(tmp_path, capsys, pair):
    """Quarantined where the second phone's samples begin, and split there into two walks that
    run clean."""
    from workstation.graph.importers import graph_from_tra

    a, b = (need(IPIN / "logfiles" / f"IPIN2023_T3_TrainingTrial{n}.txt") for n in pair)
    graph = tmp_path / "museum.yaml"
    graph_from_tra(sorted((IPIN / "supplementary" / "trajectories").glob("*.tra"))).save(graph)
    joined = tmp_path / "joined.txt"
    at = join_gsd(a, b, joined)
    s = load_session(joined)
    jump = s.metadata.clock_jump
    assert jump is not None and "another phone's sensor" in jump.what
    assert abs(jump.t - inertial_start(s) - at) <= 0.1
    quarantined_then_split_clean(joined, graph, tmp_path, capsys, "resolution")


@pytest.mark.shared_data
def test_two_museum_walks_of_one_phone_joined_say_nothing_of_a_second_phone(tmp_path):
    a, b = (need(IPIN / "logfiles" / f"IPIN2023_T3_TrainingTrial{n}.txt") for n in A520F)
    join_gsd(a, b, tmp_path / "one.txt")
    jump = load_session(tmp_path / "one.txt").metadata.clock_jump
    assert jump is None or "resolution" not in jump.what
