"""``workstation layouts``: the Rerun blueprints of layouts/, written again."""

from __future__ import annotations


def run(args) -> int:
    from workstation.viz.layouts import write_layouts  # loads Rerun

    for p in write_layouts(args.out):
        print(f"wrote {p}")
    return 0
