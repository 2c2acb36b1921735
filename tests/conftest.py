"""Shared fixtures: where ../shared/data is, and tiny synthetic logfiles."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("WORKSTATION_SHARED_DATA", REPO.parent / "shared" / "data"))
IPIN = SHARED_DATA / "ipin2023-track3"
MSILC = SHARED_DATA / "microsoft-ilc2020-sample" / "site1" / "F1"
UJI = SHARED_DATA / "ujiindoorloc"


def need(path: Path) -> Path:
    """Skip the test cleanly when a piece of ../shared/data is absent."""
    if not path.exists():
        pytest.skip(f"shared data not present: {path}")
    return path


@pytest.fixture
def ipin_logfile():
    def get(name: str = "IPIN2023_T3_TrainingTrial51_repetition02.txt") -> Path:
        return need(IPIN / "logfiles" / name)

    return get


def gsd_lines(seconds: float = 4.0, rate: float = 50.0, with_pres: bool = True) -> list[str]:
    """A small, valid GetSensorData logfile body (header + IMU, PRES, WIFI, POSI records)."""
    out = [
        "% LogFile created by the 'GetSensorData' App for Android.",
        "% Manufacturer:            \tsamsung",
        "% Model:                   \tSM-TEST",
    ]
    n = int(seconds * rate)
    for i in range(n):
        app = 0.05 + i / rate + 0.003 * (i % 3)
        sen = 1000.0 + i / rate
        out.append(f"ACCE;{app:.4f};{sen:.4f};0.1;0.2;9.8;3")
        out.append(f"GYRO;{app:.4f};{sen:.4f};0.01;0.02;0.03;3")
        out.append(f"MAGN;{app:.4f};{sen:.4f};20.0;-5.0;-40.0;3")
        if with_pres and i % 5 == 0:
            out.append(f"PRES;{app:.4f};{sen:.4f};{976.5 + 0.001 * i:.4f};3")
        if i % 100 == 50:
            for ap in range(3):
                out.append(
                    f"WIFI;{app:.4f};{sen:.4f};SSID{ap};20:23:00:00:00:0{ap};2412;{-50 - 10 * ap}"
                )
    out.append("POSI;1.0;1;49.4612;11.1116;0;100")
    out.append("POSI;3.0;2;49.4613;11.1117;-1;100")
    out.append("GNSS;1.2;1686739901.999;49.46;11.11;380.2;171.7;4.0;0.4;18;8")
    return out


MUTATIONS = ("truncate", "insert", "replace_field", "drop_sep", "dup_sep")


def mutate(line: str, sep: str, mode: str, cut: int, junk: str) -> str:
    """One corrupted log line (for the property tests of the readers)."""
    fields = line.split(sep)
    if mode == "truncate":
        return line[: cut % (len(line) + 1)]
    if mode == "insert":
        k = cut % (len(line) + 1)
        return line[:k] + junk + line[k:]
    if mode == "replace_field":
        fields[cut % len(fields)] = junk
        return sep.join(fields)
    if mode == "drop_sep":
        return line.replace(sep, "", 1 + cut % 3)
    return line.replace(sep, sep + sep, 1)


def line_edits(n_lines: int, junk: list[str]):
    """A hypothesis strategy: 1–3 edits (line, cut, junk, mutation) of a text of ``n_lines``
    lines — random text or one of ``junk`` — for the bulk-against-line-reader tests."""
    from hypothesis import strategies as st

    return st.lists(
        st.tuples(
            st.integers(min_value=0, max_value=n_lines - 1),
            st.integers(min_value=0, max_value=60),
            st.text(alphabet=st.characters(codec="utf-8", exclude_characters="\n"), max_size=8)
            | st.sampled_from(junk),
            st.sampled_from(MUTATIONS),
        ),
        min_size=1,
        max_size=3,
    )


def write_edited(path: Path, base: list[str], edits, sep: str) -> Path:
    """``base`` with ``edits`` (:func:`line_edits`) applied, written to ``path`` as bytes."""
    lines = list(base)
    for idx, cut, junk, mode in edits:
        lines[idx] = mutate(lines[idx], sep, mode, cut, junk)
    path.write_bytes("\n".join(lines).encode("utf-8", errors="surrogatepass"))
    return path


def session_lists(s) -> list:
    """Every stream of a session as plain lists: two readers' sessions compared exactly."""
    arrays = [s.accelerometer.t, s.accelerometer.xyz, s.gyroscope.t, s.gyroscope.xyz,
              s.magnetometer.t, s.magnetometer.xyz, s.wifi.t, s.wifi.rss_dbm, s.wifi.bssid,
              s.wifi.ssid, s.wifi.freq_mhz]  # fmt: skip
    if s.pressure is not None:
        arrays += [s.pressure.t, s.pressure.value]
    if s.ground_truth is not None:
        arrays += [s.ground_truth.t, s.ground_truth.x, s.ground_truth.y, s.ground_truth.floor]

    def plain(a):  # NaN as None: a floor left unknown compares equal to itself
        import numpy as np

        a = np.asarray(a)
        return (np.where(np.isnan(a), None, a.astype(object)) if a.dtype.kind == "f" else a).tolist()

    return [plain(a) for a in arrays]


def read_outcome(read, path):
    """What a reader makes of ``path``: its session as lists with its metadata, or its error
    (message and line) — compared whole between two readers."""
    from workstation.errors import InputError

    try:
        s = read(path)
    except InputError as e:
        return f"{e} @ {e.line}"
    return session_lists(s), s.metadata
