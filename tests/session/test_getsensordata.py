import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import MUTATIONS, gsd_lines, line_edits, mutate, read_outcome, write_edited
from workstation.errors import InputError
from workstation.session import load_session, read_getsensordata


def write(tmp_path, lines, name="log.txt"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def test_reads_every_stream_on_the_sensor_clock(tmp_path):
    s = read_getsensordata(write(tmp_path, gsd_lines()))
    assert len(s.accelerometer) == 200 and len(s.gyroscope) == 200 and len(s.magnetometer) == 200
    assert s.accelerometer.rate_hz == pytest.approx(50.0, rel=1e-6)  # app-clock jitter removed
    assert len(s.pressure) == 40 and s.pressure.rate_hz == pytest.approx(10.0, rel=1e-6)
    assert s.wifi.n_scans == 2 and len(s.wifi) == 6
    assert set(s.wifi.access_points) == {f"20:23:00:00:00:0{i}" for i in range(3)}
    assert s.metadata.device == "samsung SM-TEST"
    assert s.metadata.skipped == {"GNSS": 1}
    gt = s.ground_truth
    assert list(gt.floor) == [0.0, -1.0]
    # 0.0001 deg of latitude is ~11.1 m north; of longitude at 49.46 N ~7.2 m east
    assert gt.y[1] - gt.y[0] == pytest.approx(11.12, abs=0.02)
    assert gt.x[1] - gt.x[0] == pytest.approx(7.24, abs=0.02)


def test_matrix_puts_each_reading_in_its_scan(tmp_path):
    s = read_getsensordata(write(tmp_path, gsd_lines()))
    times, bssids, r = s.wifi.matrix()
    assert r.shape == (2, 3)
    assert np.array_equal(r[:, 0], [-50, -50]) and np.array_equal(r[:, 2], [-70, -70])
    _, _, r2 = s.wifi.matrix(bssids=np.array(["20:23:00:00:00:02", "zz"]))
    assert np.array_equal(r2[:, 0], [-70, -70]) and np.isnan(r2[:, 1]).all()


def test_malformed_number_names_file_and_line(tmp_path):
    lines = gsd_lines()
    lines[10] = "ACCE;0.5;1000.5;0.1;abc;9.8;3"
    with pytest.raises(InputError) as e:
        read_getsensordata(write(tmp_path, lines))
    assert e.value.line == 11 and "log.txt:11" in str(e.value) and "'abc'" in str(e.value)


def test_short_record_names_the_layout(tmp_path):
    lines = gsd_lines()
    lines[20] = "WIFI;1.0;2.0;ssid"
    with pytest.raises(InputError, match=r"log.txt:21: WIFI record has 3 fields, expected 6"):
        read_getsensordata(write(tmp_path, lines))


def test_non_finite_value_is_an_error(tmp_path):
    lines = gsd_lines()
    lines[5] = "GYRO;0.5;1000.5;nan;0.1;0.1;3"
    with pytest.raises(InputError, match="not a finite number"):
        read_getsensordata(write(tmp_path, lines))


def test_empty_file_and_no_accelerometer(tmp_path):
    with pytest.raises(InputError, match="empty"):
        read_getsensordata(write(tmp_path, [""]))
    no_acc = [ln for ln in gsd_lines() if not ln.startswith("ACCE")]
    with pytest.raises(InputError, match="no accelerometer"):
        read_getsensordata(write(tmp_path, no_acc))


def test_missing_barometer_is_a_warning(tmp_path):
    s = read_getsensordata(write(tmp_path, gsd_lines(with_pres=False)))
    assert s.pressure is None
    assert any("no barometer" in w for w in s.warnings)


def test_unsorted_and_duplicated_timestamps_are_sorted_and_reported(tmp_path):
    lines = gsd_lines()
    acc = [i for i, ln in enumerate(lines) if ln.startswith("ACCE")]
    lines[acc[3]], lines[acc[7]] = lines[acc[7]], lines[acc[3]]  # two samples swapped
    lines.insert(acc[10] + 1, lines[acc[10]])  # one sample repeated
    s = read_getsensordata(write(tmp_path, lines))
    assert np.all(np.diff(s.accelerometer.t) > 0)
    assert len(s.accelerometer) == 200
    assert any("out of time order" in w for w in s.warnings)
    assert any("repeated timestamp" in w for w in s.warnings)


def test_garbage_line_is_reported(tmp_path):
    lines = gsd_lines()
    lines[30] = "this is not a record"
    with pytest.raises(InputError) as e:
        load_session(write(tmp_path, lines))
    assert e.value.line == 31


BASE = gsd_lines(seconds=2.0)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    idx=st.integers(min_value=3, max_value=len(BASE) - 1),
    cut=st.integers(min_value=0, max_value=60),
    junk=st.text(alphabet=st.characters(codec="utf-8", exclude_characters="\n\r"), max_size=12),
    mode=st.sampled_from(MUTATIONS),
)
def test_mutated_lines_give_only_the_typed_error(tmp_path, idx, cut, junk, mode):
    lines = list(BASE)
    lines[idx] = mutate(lines[idx], ";", mode, cut, junk)
    try:
        s = load_session(write(tmp_path, lines))
    except InputError as e:
        assert e.path and str(e.path).endswith("log.txt")
        return
    # Accepted: the session must still be well-formed.
    assert np.all(np.diff(s.accelerometer.t) > 0)
    assert np.all(np.isfinite(s.accelerometer.xyz))


@pytest.mark.shared_data
def test_ipin_s7_rates(ipin_logfile):
    s = load_session(ipin_logfile())
    summ = s.info().streams
    for name in ("accelerometer", "gyroscope", "magnetometer"):
        assert summ[name].rate_hz == pytest.approx(50.0, abs=1.0)
    assert summ["pressure"].rate_hz == pytest.approx(10.0, abs=0.5)
    assert s.wifi.n_scans == 105
    assert len(s.ground_truth) == 16 and set(s.ground_truth.floors) == {-2.0, -1.0, 0.0}
    assert s.metadata.skipped["AHRS"] == 15078
    assert s.warnings == []


@pytest.mark.shared_data
def test_ipin_a5_gyro_at_100hz(ipin_logfile):
    s = load_session(ipin_logfile("IPIN2023_T3_TrainingTrial01_repetition01.txt"))
    assert s.gyroscope.rate_hz == pytest.approx(100.0, abs=2.0)
    assert s.pressure.rate_hz == pytest.approx(6.2, abs=0.3)


def _read(path, bulk: bool):
    """The session (or the error text) read in bulk, or line by line."""
    from workstation.session import getsensordata

    with pytest.MonkeyPatch.context() as mp:
        if not bulk:
            mp.setattr(getsensordata, "split_records", lambda *a: None)
        return read_outcome(read_getsensordata, path)


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(edits=line_edits(len(BASE), ["nan", "inf", " ", "\t", "1_0", "١", "", "%", "ACCE", "ab;"]))
def test_bulk_reader_matches_the_line_reader(tmp_path, edits):
    """The vectorized reader (issue #17) gives the line-by-line reader's session, warnings and
    errors (message and line) on mutated files."""
    p = write_edited(tmp_path / "log.txt", BASE, edits, ";")
    assert _read(p, bulk=True) == _read(p, bulk=False)


@pytest.mark.shared_data
def test_bulk_reader_matches_the_line_reader_on_real_logfiles(ipin_logfile):
    p = ipin_logfile("IPIN2023_T3_TrainingTrial04_repetition01.txt")
    assert _read(p, bulk=True) == _read(p, bulk=False)


@pytest.mark.parametrize("packed", [False, True])
def test_a_byte_order_mark_is_read_past(tmp_path, packed):
    """Issue #51: a logfile saved by an editor with a UTF-8 BOM was refused ("not a
    GetSensorData record") though the rest was fine."""
    import gzip

    plain = read_getsensordata(write(tmp_path, gsd_lines()))
    data = b"\xef\xbb\xbf" + ("\n".join(gsd_lines()) + "\n").encode()
    p = tmp_path / "bom.txt"
    p.write_bytes(gzip.compress(data) if packed else data)
    s = load_session(p)
    assert np.array_equal(s.accelerometer.xyz, plain.accelerometer.xyz)
    assert s.metadata.device == plain.metadata.device
