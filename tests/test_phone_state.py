"""Two walks joined with every clock re-timed, seen by the phone's own state (issue #67 item 2;
session/clocks.py ``calibration_change``): a Microsoft ILC file's uncalibrated magnetometer
rows report the hard-iron bias the phone subtracted, one estimate per recording. Where another
estimate begins and the raw field jumps there, a second recording begins; a re-estimate within
one recording leaves the raw field running on and is no join. No real walk here shows one."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import REPO, SHARED_DATA, need
from tests.test_two_clocks import _rows, join_ilc, quarantined_then_split_clean
from workstation.session import load_session
from workstation.session.clocks import BIAS_TOL_UT, MIN_BLOCK, RAW_JUMP_UT, calibration_change

MSILC = REPO / "tests" / "data" / "msilc"
GRAPH = MSILC / "site1_f1_graph.yaml"
FLOORS = ("f1", "f2", "f3", "b1")


def _walk(rng, n: int = 1500) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A phone's uncalibrated magnetometer at 50 Hz: the raw field wandering as a walker turns
    (steps of ~1.5 µT a sample) and one bias estimate."""
    t = np.arange(n) * 0.02
    raw = np.array([20.0, -60.0, -330.0]) + np.cumsum(rng.normal(0, 1.5, (n, 3)), axis=0)
    bias = np.tile(rng.normal([-50, -80, -290], 20), (n, 1))
    return t, raw, bias


@pytest.mark.parametrize("seed", range(4))
def test_another_recording_s_calibration_where_the_raw_field_jumps_is_a_second_recording(seed):
    rng = np.random.default_rng(seed)
    t, raw, bias = _walk(rng)
    assert calibration_change(t, raw, bias) is None  # one recording, one estimate
    k = int(rng.integers(300, 1200))
    other = rng.normal(0, 1, 3)
    bias2, raw2 = bias.copy(), raw.copy()
    bias2[k:] += other / np.linalg.norm(other) * rng.uniform(2, 90)  # another estimate …
    assert calibration_change(t, raw2, bias2) is None  # … the raw field running on: re-estimated
    jump = rng.normal(0, 1, 3)
    raw2[k:] += jump / np.linalg.norm(jump) * rng.uniform(1.5 * RAW_JUMP_UT, 80)  # elsewhere
    found = calibration_change(t, raw2, bias2)
    assert found is not None and found[0] == pytest.approx(t[k])
    assert "calibration" in found[1] and "raw" in found[1]


@pytest.mark.parametrize("seed", range(3))
def test_a_few_stray_estimates_or_a_change_within_the_tolerance_are_no_join(seed):
    rng = np.random.default_rng(seed)
    t, raw, bias = _walk(rng)
    k = int(rng.integers(300, 1200))
    raw2, bias2 = raw.copy(), bias.copy()
    raw2[k:] += 40.0
    bias2[k : k + MIN_BLOCK - 2] += 30.0  # a glitch of a few samples
    assert calibration_change(t, raw2, bias2) is None
    bias2 = bias.copy()
    bias2[k:] += np.array([0.8, 0, 0]) * BIAS_TOL_UT  # the same estimate, rounded otherwise
    assert calibration_change(t, raw2, bias2) is None


@pytest.mark.parametrize("pair", [(0, 8), (3, 9)])
def test_two_path_files_of_two_phone_states_joined_with_every_clock_re_timed(
    tmp_path, capsys, pair
):
    """The bundled walks 0 and 3 and 8 and 9 were recorded with different calibrations: joined
    with every clock re-timed (the WiFi's too), found where the second recording begins,
    quarantined, and split there into two walks that run clean."""
    files = sorted(MSILC.glob("*.txt.gz"))
    joined = tmp_path / "joined.txt"
    join_ilc(files[pair[0]], files[pair[1]], joined, careful=True)
    first = load_session(files[pair[0]])
    ends = max(first.accelerometer.t[-1], first.gyroscope.t[-1])
    s = load_session(joined)
    jump = s.metadata.clock_jump
    assert jump is not None and "calibration" in jump.what
    assert ends < jump.t <= ends + 0.5  # the second recording's first samples
    quarantined_then_split_clean(joined, GRAPH, tmp_path, capsys, "calibration")
    assert abs(load_session(tmp_path / "parts" / "joined-1").duration - ends) <= 0.5


def test_one_phone_state_joined_says_nothing_and_malformed_state_refuses_nothing(tmp_path):
    """Walks 0 and 1 share their calibration (recorded one after the other): the phone's state
    says nothing. A walk whose calibration rows are cut short or garbled reads as before — the
    rows are evidence, not a stream — and says nothing either."""
    files = sorted(MSILC.glob("*.txt.gz"))
    joined = tmp_path / "joined.txt"
    join_ilc(files[0], files[1], joined, careful=True)
    assert load_session(joined).metadata.clock_jump is None
    head, rows = _rows(files[8])
    plain = load_session(files[8])
    for how in ("short", "nan"):
        bad = [list(r) for r in rows]
        for r in bad[: len(bad) // 2]:
            if r[1] == "TYPE_MAGNETIC_FIELD_UNCALIBRATED":
                r[5:] = r[5:6] if how == "short" else ["nan", "1", "2", "3"]
        p = tmp_path / f"{how}.txt"
        p.write_text("\n".join(head + ["\t".join(r) for r in bad]) + "\n")
        s = load_session(p)
        assert s.metadata.clock_jump is None
        assert np.array_equal(s.magnetometer.xyz, plain.magnetometer.xyz)
        assert s.metadata.skipped == plain.metadata.skipped


def test_no_real_walk_of_the_four_floors_shows_two_phone_states():
    """Every walk of the mall's four floors (451 with the phone's calibration; one re-estimated
    it by 3.6 µT while its raw field ran on): none shows a second recording."""
    walks = []
    for f in FLOORS:
        walks += sorted(
            need(SHARED_DATA / f"microsoft-ilc2020-site1-{f}" / "path_data_files").glob("*.gz")
        )
    assert len(walks) >= 450
    assert [w.name for w in walks if load_session(w).metadata.clock_jump is not None] == []
