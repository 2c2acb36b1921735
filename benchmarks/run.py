"""Run every benchmark and print its figures: `make bench` or `python benchmarks/run.py [name...]`."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

BENCHES = [
    "bench_load",
    "bench_pipeline",
    "bench_rerun",
    "bench_editor",
    "bench_localize",
    "bench_campaign",
]


def main(names: list[str]) -> int:
    for name in names or BENCHES:
        mod = importlib.import_module(name if name.startswith("bench_") else f"bench_{name}")
        mod.run().print()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
