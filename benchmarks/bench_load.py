"""Loading logfiles: median latency per file (9 loads, with the spread), MB/s and multiples of
real time (walk seconds per second)."""

from __future__ import annotations

from _common import SHARED_DATA, Table, median_of

from workstation.session import load_session


def run() -> Table:
    t = Table("Session loading")
    files = sorted((SHARED_DATA / "ipin2023-track3" / "logfiles").glob("*.txt"))
    files += sorted(
        (SHARED_DATA / "microsoft-ilc2020-sample" / "site1" / "F1" / "path_data_files").glob(
            "*.txt"
        )
    )[:1]
    if not files:
        print("  (../shared/data absent: no logfiles to time)")
        return t
    ipin = [f for f in files if f.name.startswith("IPIN")]
    largest = max(ipin, key=lambda f: f.stat().st_size) if ipin else None
    for f in dict.fromkeys([*files[:3], largest, files[-1]]):
        if f is None:
            continue
        s = load_session(f)  # warm: imports and the file cache
        sec, iqr = median_of(lambda f=f: load_session(f), repeat=9)
        mb = f.stat().st_size / 1e6
        t.add(f"{f.name[:44]} ({mb:.1f} MB), median", sec * 1e3, "ms", "{:,.0f}")
        t.add("   interquartile range", iqr * 1e3, "ms", "{:,.0f}")
        t.add("   throughput", mb / sec, "MB/s")
        t.add("   speed", s.duration / sec, "x real time", "{:,.0f}")
    return t
