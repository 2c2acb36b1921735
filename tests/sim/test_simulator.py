"""The simulator against the properties a real phone walk has (issue: walk simulator)."""

import numpy as np
import pytest
from scipy.signal import find_peaks

from tests.conftest import REPO
from workstation.building.floorplan import FloorPlan
from workstation.graph import LandmarkGraph
from workstation.session import load_session
from workstation.sim import simulate, survey_points
from workstation.sim.building import office2f

SAMPLES = REPO / "sample_sessions" / "office2f"


@pytest.fixture(scope="module")
def normal():
    return simulate("office2f", "normal", seed=1, model="ideal")


@pytest.fixture(scope="module")
def varied():
    return simulate("office2f", "varied", seed=1, model="ideal")


def vertical_rate(s):
    """Gyro rate about gravity (gravity = low-passed accelerometer)."""
    k = 25
    acc = s.accelerometer.xyz
    g = np.stack([np.convolve(acc[:, i], np.ones(k) / k, mode="same") for i in range(3)], axis=1)
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    return np.einsum("ij,ij->i", s.gyroscope.xyz, g)


def test_route_and_building_are_paper_like():
    b = office2f()
    pts = b.route_points("survey")
    assert 340 <= np.hypot(*np.diff(pts[:, :2], axis=0).T).sum() <= 380
    assert set(pts[:, 2]) == {0.0, 1.0}
    for f in (0.0, 1.0):
        outline = b.plan.floors[f].outline
        w, h = np.ptp(outline, axis=0)
        assert 2000 <= w * h <= 6000


def test_step_rate_and_variation(normal):
    s, meta = normal.session, normal.session.metadata.extra
    walking_s = np.count_nonzero(s.ground_truth.walking) / s.accelerometer.rate_hz
    rate = meta["true_step_count"] / walking_s
    assert 1.6 <= rate <= 2.2
    # the accelerometer shows one magnitude peak per step
    mag = np.linalg.norm(s.accelerometer.xyz, axis=1)
    peaks, _ = find_peaks(mag, height=10.8, distance=12)
    assert abs(peaks.size - meta["true_step_count"]) <= 0.05 * meta["true_step_count"]
    periods = np.diff(s.accelerometer.t[peaks])
    walking_periods = periods[(periods > 0.35) & (periods < 0.8)]
    assert 0.005 < np.std(walking_periods) < 0.06  # natural, not metronomic


def test_turn_rates_at_corners(normal):
    s = normal.session
    rate = vertical_rate(s)
    t = s.gyroscope.t
    passes = s.metadata.extra["landmark_passes"][:-1]  # the walk ends at the last one: no turn
    corners = [(tt, n) for tt, n in passes if n[:2] in ("SW", "SE", "NE", "NW")]
    assert len(corners) >= 6
    for tt, n in corners:
        m = (t > tt - 1.0) & (t < tt + 1.5)
        assert np.abs(rate[m]).max() > 1.3, n
    straight = (t > 10) & (t < 18)  # walking straight south from W0 to SW0
    assert np.abs(rate[straight]).max() < 0.6


def test_pressure_per_floor_and_noise(normal):
    s = normal.session
    fl = np.interp(s.pressure.t, s.ground_truth.t, s.ground_truth.floor)
    p0 = np.median(s.pressure.value[fl == 0])
    p1 = np.median(s.pressure.value[fl == 1])
    assert p0 - p1 == pytest.approx(0.45, abs=0.05)  # pressure falls as you climb
    assert s.pressure.rate_hz == pytest.approx(10.0)
    still = s.pressure.value[: int(7 * s.pressure.rate_hz)]
    assert 0.005 < np.std(still) < 0.03


def test_doors_stop_the_walker(normal):
    s = normal.session
    gt = s.ground_truth
    doors = [(tt, n) for tt, n in s.metadata.extra["landmark_passes"] if n[:2] in ("DS", "DN")]
    assert len(doors) == 4
    for tt, _ in doors:
        m = (gt.t >= tt) & (gt.t <= tt + 10)
        still = np.flatnonzero(gt.walking[m] == 0)
        dur = still.size / 50.0
        assert 1.0 <= dur <= 8.0


def test_elevator_stands_still_while_pressure_changes(normal):
    s = normal.session
    (t_ride,) = [tt for tt, k, _ in s.metadata.extra["events"] if k == "elevator"]
    m = (s.ground_truth.t > t_ride) & (s.ground_truth.t < t_ride + 6)
    assert not s.ground_truth.walking[m].any()
    pm = (s.pressure.t > t_ride - 1) & (s.pressure.t < t_ride + 10)
    assert np.ptp(s.pressure.value[pm]) > 0.35


def test_wifi_ranges_and_scan_interval(normal):
    w = normal.session.wifi
    assert w.rss_dbm.min() >= -100 and w.rss_dbm.max() <= -25
    assert np.all(w.rss_dbm == np.round(w.rss_dbm))
    dt = np.diff(w.scan_times)
    assert dt.min() >= 2.0 and dt.max() <= 4.0
    per_scan = np.bincount(np.unique(w.t, return_inverse=True)[1])
    assert 5 <= np.median(per_scan) <= 24


def test_magnetic_disturbance_zones_bend_the_field(normal):
    s = normal.session
    strength = np.linalg.norm(s.magnetometer.xyz, axis=1)
    assert np.ptp(strength) > 15  # clean field is ~48 µT everywhere; zones add up to 25 µT


def test_varied_walk_has_its_disturbances(varied, normal):
    kinds = [k for _, k, _ in varied.session.metadata.extra["events"]]
    for k in ("false_walking", "stop", "mid_turn"):
        assert k in kinds
    assert "false_walking" not in [k for _, k, _ in normal.session.metadata.extra["events"]]
    # false walking: the accelerometer varies while the walker stands still
    s = varied.session
    t0, _, _ = next(e for e in s.metadata.extra["events"] if e[1] == "false_walking")
    m = (s.accelerometer.t > t0 + 1) & (s.accelerometer.t < t0 + 3)
    assert not s.ground_truth.walking[m].any()
    assert np.var(np.linalg.norm(s.accelerometer.xyz[m], axis=1)) > 0.5


def test_deterministic_for_a_seed():
    a = simulate("office2f", "varied", seed=3).session
    b = simulate("office2f", "varied", seed=3).session
    c = simulate("office2f", "varied", seed=4).session
    assert np.array_equal(a.accelerometer.xyz, b.accelerometer.xyz)
    assert np.array_equal(a.wifi.rss_dbm, b.wifi.rss_dbm)
    assert not np.array_equal(a.accelerometer.t, c.accelerometer.t) or not np.array_equal(
        a.accelerometer.xyz, c.accelerometer.xyz
    )


def test_manual_survey_grid():
    b = office2f()
    rp = survey_points(b)
    assert 200 <= rp.shape[0] <= 260
    sim = simulate("office2f", "survey5", seed=1)
    s = sim.session
    assert s.metadata.extra["kind"] == "manual_survey"
    assert s.wifi.n_scans == 5 * rp.shape[0]
    gx, gy, gf = s.ground_truth.at(s.wifi.scan_times)
    assert np.unique(np.round(np.column_stack([gx, gy, gf]), 3), axis=0).shape[0] == rp.shape[0]


def test_walls_block_the_signal():
    from workstation.sim.wifi import RadioModel

    b = office2f()
    radio = RadioModel(b)
    # same distance from an AP, one point behind more walls, averaged over shadowing
    ap = b.access_points[9]  # (40, 25) floor 0, in the core
    rss_floor0 = radio.mean_rss([ap.x + 8], [ap.y], [0.0])[0, 9]
    rss_floor1 = radio.mean_rss([ap.x + 8], [ap.y], [1.0])[0, 9]
    assert rss_floor0 - rss_floor1 > 10


@pytest.mark.parametrize("walk", ["normal", "varied", "heldout", "survey5", "survey10"])
def test_bundled_samples_load_and_their_graphs_validate(walk):
    folder = SAMPLES / walk
    s = load_session(folder)
    g = LandmarkGraph.load(folder / "graph.yaml")
    plan = FloorPlan.load(folder / "floorplan.yaml")
    assert len(g.nodes) == 20 and set(plan.floors) == {0.0, 1.0}
    assert s.ground_truth is not None and s.wifi.n_scans > 90


def test_bundled_normal_walk_is_what_the_simulator_makes():
    bundled = load_session(SAMPLES / "normal")
    model = bundled.metadata.extra.get("model", "ideal")
    fresh = simulate("office2f", "normal", seed=1, model=model).session
    assert np.array_equal(fresh.accelerometer.xyz, bundled.accelerometer.xyz)
    assert np.array_equal(fresh.wifi.rss_dbm, bundled.wifi.rss_dbm)
