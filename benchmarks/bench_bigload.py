"""Loading a 200 MB GetSensorData logfile: wall time and the process's peak memory (issue #17:
≤ 700 MB). The file is the museum's Trial51 walk repeated with its times shifted, built once
under the system's temporary folder."""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

from _common import SHARED_DATA, Table

SRC = SHARED_DATA / "ipin2023-track3" / "logfiles" / "IPIN2023_T3_TrainingTrial51_repetition02.txt"
TARGET_MB = 200
_TIMED = re.compile(rb"^(ACCE|GYRO|MAGN|PRES|WIFI|AHRS|LIGH|SOUN);([0-9.]+);([0-9.]+);", re.M)

# the process's own peak, VmHWM (getrusage's ru_maxrss carries the peak of the process that
# started it across exec: the benchmarks' process, grown by the benchmarks before)
PROBE = """
import re, sys, time
from pathlib import Path
from workstation.session import load_session
def peak_mb():
    return int(re.search(r"VmHWM:\\s+(\\d+) kB", Path("/proc/self/status").read_text())[1]) / 1024
base = peak_mb()
t = time.perf_counter()
s = load_session(sys.argv[1])
sec = time.perf_counter() - t
print(sec, base, peak_mb(), s.duration)
"""


def big_logfile() -> Path:
    out = Path(tempfile.gettempdir()) / f"workstation-bench-{TARGET_MB}MB.txt"
    if out.is_file():
        return out
    data = SRC.read_bytes()
    head, _, body = data.partition(b"\nACCE;")
    body = b"ACCE;" + body
    span = 400.0  # seconds per copy: more than the walk lasts
    reps = int(TARGET_MB * 1e6 // len(body)) + 1
    tmp = out.with_suffix(".part")
    with open(tmp, "wb") as f:
        f.write(head + b"\n")
        for k in range(reps):
            shift = k * span
            f.write(_TIMED.sub(lambda m, s=shift: b"%s;%.4f;%.4f;" % (
                m[1], float(m[2]) + s, float(m[3]) + s), body))  # fmt: skip
    tmp.replace(out)
    return out


def run() -> Table:
    t = Table("Loading a 200 MB logfile")
    if not SRC.is_file():
        print("  (../shared/data absent: no logfile to grow)")
        return t
    path = big_logfile()
    mb = path.stat().st_size / 1e6
    res = subprocess.run([sys.executable, "-c", PROBE, str(path)], capture_output=True,
                         text=True, check=True)  # fmt: skip
    sec, base, peak, dur = map(float, res.stdout.split())
    t.add(f"{path.name} ({mb:,.0f} MB, {dur / 3600:.1f} h of walking)", sec, "s", "{:,.2f}")
    t.add("   throughput", mb / sec, "MB/s")
    t.add("   peak memory of the process", peak, "MB", "{:,.0f}")
    t.add("   of which before loading (imports)", base, "MB", "{:,.0f}")
    return t


if __name__ == "__main__":
    run().print()
