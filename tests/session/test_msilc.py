import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import MSILC, MUTATIONS, REPO, line_edits, mutate, read_outcome, write_edited
from workstation.errors import InputError
from workstation.session import load_session, read_msilc
from workstation.session.msilc import floor_number


def ilc_lines():
    t0 = 1574561832944
    out = [
        f"#\tstartTime:{t0}",
        "#\tSiteID:abc\tSiteName:mall\tFloorId:f\tFloorName:F2",
        "#\tBrand:OPPO\tModel:PBCM10",
    ]
    rows = []
    for i in range(100):
        ms = t0 + 100 + 20 * i
        rows.append(f"{ms}\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3")
        rows.append(f"{ms}\tTYPE_GYROSCOPE\t0.0\t0.0\t0.1\t3")
        rows.append(f"{ms}\tTYPE_MAGNETIC_FIELD\t20\t5\t-40\t3")
        rows.append(f"{ms}\tTYPE_ROTATION_VECTOR\t0.1\t0.0\t0.2\t3")
        # the raw field and the bias the phone subtracted (evidence of the recording: clocks.py)
        rows.append(f"{ms}\tTYPE_MAGNETIC_FIELD_UNCALIBRATED\t-27.8\t-76.4\t-332.4\t-47.8\t-81.4"
                    "\t-292.4\t3")
    scan1, scan2 = t0 + 1000, t0 + 3000
    rows += [
        f"{scan1}\tTYPE_WIFI\tnet\t00:00:00:00:00:01\t-50\t2412\t{scan1 - 300}",
        f"{scan1}\tTYPE_WIFI\tnet\t00:00:00:00:00:02\t-60\t2412\t{scan1 - 9000}",  # stale: 9 s old
        f"{scan2}\tTYPE_WIFI\t\t00:00:00:00:00:01\t-55\t5180\t{scan2 - 200}",
        f"{scan2}\tTYPE_WIFI\tnet\t00:00:00:00:00:03\t-65\t2412\t{scan1 - 100}",  # cached before scan1
    ]
    rows.append(f"{t0 + 500}\tTYPE_WAYPOINT\t10.0\t20.0")
    rows.append(f"{t0 + 2100}\tTYPE_WAYPOINT\t12.0\t21.0")
    rows.reverse()  # out of time order, as in the real files
    return out + rows + [f"#\tendTime:{t0 + 3100}"]


def write(tmp_path, lines):
    p = tmp_path / "walk.txt"
    p.write_text("\n".join(lines) + "\n")
    return p


def test_sorted_streams_stale_wifi_dropped_floor_from_header(tmp_path):
    s = load_session(write(tmp_path, ilc_lines()))
    assert s.metadata.source == "msilc"
    assert np.all(np.diff(s.accelerometer.t) > 0) and len(s.accelerometer) == 100
    assert s.accelerometer.t[0] == pytest.approx(0.1)
    assert s.wifi.n_scans == 2
    assert sorted(s.wifi.bssid.tolist()) == ["00:00:00:00:00:01", "00:00:00:00:00:01"]
    assert s.metadata.skipped["TYPE_WIFI (stale)"] == 2
    assert s.metadata.skipped["TYPE_ROTATION_VECTOR"] == 100
    assert s.pressure is None and any("barometer" in w for w in s.warnings)
    assert list(s.ground_truth.floor) == [1.0, 1.0]
    assert s.ground_truth.t.tolist() == pytest.approx([0.5, 2.1])


def test_bad_row_names_line(tmp_path):
    lines = ilc_lines()
    i = next(k for k, ln in enumerate(lines) if "TYPE_ACCELEROMETER" in ln)
    lines[i] = lines[i].replace("\t9.8\t", "\t9,8\t")
    with pytest.raises(InputError, match="'9,8' is not a finite number") as e:
        read_msilc(write(tmp_path, lines))
    assert e.value.line == i + 1


def test_floor_names():
    assert floor_number("F1") == 0 and floor_number("F3") == 2
    assert floor_number("B1") == -1 and floor_number("2B") == -2
    assert np.isnan(floor_number("LG"))


def test_real_path_file():
    """A real path file (the shared sample's, else its gzipped copy bundled in tests/data)."""
    name = "5dd9ef829191710006b5707a.txt"
    p = MSILC / "path_data_files" / name
    if not p.exists():
        p = REPO / "tests" / "data" / "msilc_more" / f"{name}.gz"
    s = load_session(p)
    assert s.accelerometer.rate_hz == pytest.approx(50.0, abs=1.0)
    assert len(s.ground_truth) == 17
    assert s.wifi.n_scans == 31
    # every kept reading is fresh: not older than the previous scan
    assert s.metadata.skipped["TYPE_WIFI (stale)"] > 1000


def test_bundled_real_path_file_is_the_sample_session(tmp_path):
    """A real Microsoft ILC path file shipped with the tests (MIT, tests/data/msilc): it loads,
    and equals the bundled sample session converted from it — runs where ../shared/data is
    absent."""
    import gzip
    import shutil

    from tests.conftest import REPO

    src = REPO / "tests" / "data" / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"
    p = tmp_path / "5dd9efa7c5b77e0006b17367.txt"
    with gzip.open(src) as f, p.open("wb") as out:
        shutil.copyfileobj(f, out)
    s = load_session(p)
    sample = load_session(REPO / "sample_sessions" / "msilc-site1-f1-walk")
    assert s.accelerometer.rate_hz == pytest.approx(50.0, abs=1.0)
    assert len(s.ground_truth) == 13 and s.wifi.n_scans == 28
    assert s.metadata.skipped["TYPE_WIFI (stale)"] > 1000
    assert np.array_equal(s.accelerometer.t, sample.accelerometer.t)
    assert np.allclose(s.accelerometer.xyz, sample.accelerometer.xyz)
    assert np.array_equal(s.ground_truth.x, sample.ground_truth.x)


BASE = ilc_lines()


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    idx=st.integers(min_value=3, max_value=len(BASE) - 2),
    cut=st.integers(min_value=0, max_value=60),
    junk=st.text(alphabet=st.characters(codec="utf-8", exclude_characters="\n\r"), max_size=12),
    mode=st.sampled_from(MUTATIONS),
)
def test_mutated_rows_give_only_the_typed_error(tmp_path, idx, cut, junk, mode):
    lines = list(BASE)
    lines[idx] = mutate(lines[idx], "\t", mode, cut, junk)
    try:
        s = load_session(write(tmp_path, lines))
    except InputError as e:
        assert str(e.path).endswith("walk.txt")
        return
    assert np.all(np.diff(s.accelerometer.t) > 0)


def test_a_byte_order_mark_is_read_past(tmp_path):
    """Issue #51: a path file with a UTF-8 BOM reads as the same file without it."""
    plain = load_session(write(tmp_path, ilc_lines()))
    p = tmp_path / "bom.txt"
    p.write_bytes(b"\xef\xbb\xbf" + ("\n".join(ilc_lines()) + "\n").encode())
    s = load_session(p)
    assert np.array_equal(s.accelerometer.xyz, plain.accelerometer.xyz)
    assert list(s.ground_truth.floor) == list(plain.ground_truth.floor)


def _read(path, bulk: bool):
    """The session (or the error text) read in bulk, or line by line."""
    from workstation.session import msilc

    with pytest.MonkeyPatch.context() as mp:
        if bulk:  # whatever the size
            mp.setattr(msilc, "BULK_MIN_BYTES", -1)
            mp.setattr(msilc, "BULK_MIN_BYTES_LOADED", -1)
        else:
            mp.setattr(msilc, "split_tsv", lambda *a: None)
        return read_outcome(read_msilc, path)


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(edits=line_edits(len(BASE), ["nan", "inf", " ", "\t", "1_0", "١", "", "#", "#\t", "\x00",
                                    "TYPE_WIFI", "TYPE_X", "\u3000", "+1", "1e3", "5", "-1", "0.25"]))
def test_bulk_reader_matches_the_line_reader(tmp_path, edits):
    """The vectorized path-file reader (issue #53) gives the line-by-line reader's session,
    warnings and errors (message and line) on mutated files."""
    p = write_edited(tmp_path / "walk.txt", BASE, edits, "\t")
    assert _read(p, bulk=True) == _read(p, bulk=False)


def test_bulk_reader_matches_the_line_reader_on_real_path_files():
    """Every bundled Microsoft walk (gzipped) and the real sample: the same session both ways,
    and the bulk path is the one taken (not a fallback)."""
    from workstation.session import msilc
    from workstation.session._parse import read_bytes

    files = sorted((REPO / "tests" / "data" / "msilc").glob("*.txt.gz"))[:4]
    assert len(files) == 4
    for p in files:
        assert msilc.split_tsv(read_bytes(p), msilc._BULK) is not None, p
        assert _read(p, bulk=True) == _read(p, bulk=False)
