"""Run every benchmark and print its figures: `make bench` or `python benchmarks/run.py [name...]`."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

BENCHES = [
    "bench_startup",
    "bench_load",
    "bench_bigload",
    "bench_graph",
    "bench_quality",
    "bench_pipeline",
    "bench_rerun",
    "bench_editor",
    "bench_localize",
    "bench_campaign",
    "bench_store",
    "bench_plan",
    "bench_merge",
    "bench_issues",
    "bench_scale",
]
#: run only when named: the scale campaign takes most of an hour (issue #66)
ON_REQUEST = {"bench_scale"}


def main(names: list[str]) -> int:
    """Print each benchmark's table; a full run (no names) also writes benchmarks/results.json
    (the figures, the machine and the date) atomically."""
    if any(n in ("-h", "--help") for n in names):
        print(__doc__.strip() + "\nbenchmarks: " + ", ".join(b[6:] for b in BENCHES))
        return 0
    wanted = [n if n.startswith("bench_") else f"bench_{n}" for n in names]
    unknown = [n for n in wanted if n not in BENCHES]
    if unknown:
        print(f"no such benchmark: {', '.join(u[6:] for u in unknown)} "
              f"(there are: {', '.join(b[6:] for b in BENCHES)})", file=sys.stderr)  # fmt: skip
        return 2
    tables = []
    for name in wanted or [b for b in BENCHES if b not in ON_REQUEST]:
        mod = importlib.import_module(name)
        for tab in mod.tables() if hasattr(mod, "tables") else [mod.run()]:
            tab.print()
            tables.append(tab.to_dict())
    if not names:
        import datetime
        import json
        import os
        import platform

        from workstation.io.atomic import atomic_write_text

        out = {
            "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                        "python": platform.python_version()},
            "tables": tables,
        }  # fmt: skip
        path = Path(__file__).parent / "results.json"
        atomic_write_text(path, json.dumps(out, indent=1, ensure_ascii=False))
        print(f"\nwrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
