"""Odd but valid inputs (issue #18): each ends in a result or a clear message (exit 0 or 2),
never a traceback — run through the command line as a surveyor would."""

import json
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.graph import LandmarkGraph
from workstation.session import load_session
from workstation.session.model import Scalar, Vector3, WifiScans
from workstation.session.native import write_session

WALK = REPO / "sample_sessions" / "office2f" / "normal"


def _cut(s, t1):
    def v(x):
        m = x.t < t1
        return Vector3(x.t[m], x.xyz[m])

    w = s.wifi
    m = w.t < t1
    return replace(
        s,
        accelerometer=v(s.accelerometer),
        gyroscope=v(s.gyroscope),
        magnetometer=v(s.magnetometer),
        pressure=Scalar(s.pressure.t[s.pressure.t < t1], s.pressure.value[s.pressure.t < t1]),
        wifi=WifiScans(w.t[m], w.bssid[m], w.ssid[m], w.freq_mhz[m], w.rss_dbm[m]),
        ground_truth=None,
    )


def _odd(name, s):
    a = s.accelerometer
    if name == "3 s long":
        return _cut(s, s.start + 3.0)
    if name == "no WiFi":
        return replace(s, wifi=WifiScans.empty())
    if name == "no gyroscope":
        return replace(s, gyroscope=Vector3.empty())
    if name == "no magnetometer":
        return replace(s, magnetometer=Vector3.empty())
    if name == "all-zero accelerometer":
        return replace(s, accelerometer=Vector3(a.t, np.zeros_like(a.xyz)))
    if name == "no pressure":
        return replace(s, pressure=None)
    if name == "NaN pressure":
        return replace(s, pressure=Scalar(s.pressure.t, np.full(len(s.pressure), np.nan)))
    if name == "NaN accelerometer samples":
        xyz = a.xyz.copy()
        xyz[::50] = np.nan
        return replace(s, accelerometer=Vector3(a.t, xyz))
    if name == "constant pressure":
        return replace(s, pressure=Scalar(s.pressure.t, np.full(len(s.pressure), 1013.0)))
    if name == "times from 1e9 s":
        return replace(
            s,
            accelerometer=Vector3(a.t + 1e9, a.xyz),
            gyroscope=Vector3(s.gyroscope.t + 1e9, s.gyroscope.xyz),
            magnetometer=Vector3(s.magnetometer.t + 1e9, s.magnetometer.xyz),
            pressure=Scalar(s.pressure.t + 1e9, s.pressure.value),
            wifi=replace(s.wifi, t=s.wifi.t + 1e9),
            ground_truth=None,
        )
    raise AssertionError(name)


CASES = [
    "3 s long", "no WiFi", "no gyroscope", "no magnetometer", "all-zero accelerometer",
    "no pressure", "NaN pressure", "NaN accelerometer samples", "constant pressure",
    "times from 1e9 s",
]  # fmt: skip


@pytest.fixture(scope="module")
def walk():
    return load_session(WALK)


@pytest.mark.parametrize("case", CASES)
def test_odd_session_runs_or_says_why(case, walk, tmp_path, capsys):
    folder = write_session(_odd(case, walk), tmp_path / "walk")
    code = main(["run", str(folder), "--graph", str(WALK / "graph.yaml"), "--out",
                 str(tmp_path / "out")])  # fmt: skip
    out, err = capsys.readouterr()
    assert code in (0, 2, 3), (case, code, err)
    assert "Traceback" not in out + err
    if code in (0, 3):  # 3: written, but quarantined, and summary.json says why
        summary = json.loads((tmp_path / "out" / "summary.json").read_text())
        assert summary["quarantined"] == (code == 3) == bool(summary["quarantine"])
    else:
        assert err.strip(), "exit 2 says why"


def test_one_node_graph_and_a_start_not_in_the_graph(walk, tmp_path, capsys):
    one = tmp_path / "one.yaml"
    LandmarkGraph.from_dict(
        {"nodes": [{"id": "A", "x": 10, "y": 25, "floor": 0, "rules": ["gyro"]}], "edges": []}
    ).save(one)
    assert main(["run", str(WALK), "--graph", str(one), "--out", str(tmp_path / "o1"),
                 "--force"]) in (0, 2, 3)  # fmt: skip
    code = main(["run", str(WALK), "--graph", str(WALK / "graph.yaml"), "--out",
                 str(tmp_path / "o2"), "--start", "NOPE"])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 2 and "NOPE" in err and "Traceback" not in out + err


def test_an_overlong_ssid_is_refused_with_its_line(tmp_path):
    """Issue #33: one 300,000-character SSID made numpy size every SSID of the walk to it
    (info peaked at 2.4 GB on a 4-MB logfile). Text fields are bounded, refused with the line."""
    import gzip

    from tests.conftest import REPO
    from workstation.errors import InputError
    from workstation.session import load_session

    src = REPO / "tests" / "data" / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"
    lines = gzip.decompress(src.read_bytes()).decode().split("\n")
    i = next(k for k, ln in enumerate(lines) if "TYPE_WIFI" in ln)
    f = lines[i].split("\t")
    f[2] = "x" * 300_000
    lines[i] = "\t".join(f)
    p = tmp_path / "walk.txt"
    p.write_text("\n".join(lines))
    with pytest.raises(InputError, match="SSID of 300,000 characters") as e:
        load_session(p)
    assert e.value.line == i + 1


@pytest.mark.parametrize(
    "kind,factor,msg",
    [("TYPE_GYROSCOPE", 57.29578, "degrees per second"), ("TYPE_ACCELEROMETER", 1 / 9.81, "in g")],
)
def test_sensors_in_another_unit_are_refused(tmp_path, kind, factor, msg):
    """Issue #33: a gyroscope in degrees per second gave 28 m at the fixes and exit 0. A walk
    whose accelerometer does not read gravity in m/s², or whose gyroscope turns faster than
    phones measure, is refused, naming the sensor and the unit it was likely recorded in."""
    import gzip

    from tests.conftest import REPO
    from workstation.errors import InputError
    from workstation.session import load_session

    src = REPO / "tests" / "data" / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"
    lines = gzip.decompress(src.read_bytes()).decode().split("\n")
    for i, ln in enumerate(lines):
        f = ln.split("\t")
        if len(f) > 4 and f[1] == kind:
            f[2:5] = [repr(float(v) * factor) for v in f[2:5]]
            lines[i] = "\t".join(f)
    p = tmp_path / "walk.txt"
    p.write_text("\n".join(lines))
    with pytest.raises(InputError, match=msg):
        load_session(p)
    (tmp_path / "plain.txt").write_text(gzip.decompress(src.read_bytes()).decode())
    load_session(tmp_path / "plain.txt")  # as recorded: loads


def test_two_recordings_joined_in_one_file_are_refused_with_the_line(tmp_path, capsys):
    """Issue #33: walks concatenated (times jumping back) were sorted into one interleaved walk
    — 129 m at the fixes, exit 0. A jump back of more than 2 s is refused, naming its line; a
    little jitter is still only sorted."""
    from tests.conftest import gsd_lines
    from workstation.cli import main

    one = gsd_lines(seconds=6.0)
    body = [ln for ln in one if not ln.startswith("%")]
    joined = tmp_path / "joined.txt"
    joined.write_text("\n".join(one + body) + "\n")
    assert main(["info", str(joined)]) == 2
    err = capsys.readouterr().err
    first_again = len(one) + 1  # the line where the second recording begins
    assert f"joined.txt:{first_again}" in err and "time goes back" in err
    jitter = list(one)
    i = next(k for k, ln in enumerate(jitter) if ln.startswith("ACCE"))
    jitter[i], jitter[i + 3] = jitter[i + 3], jitter[i]  # two samples 60 ms out of order
    ok = tmp_path / "jitter.txt"
    ok.write_text("\n".join(jitter) + "\n")
    assert main(["info", str(ok)]) == 0
