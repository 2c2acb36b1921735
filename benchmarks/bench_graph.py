"""Reachability (the candidates of every landmark) on grid graphs with many rule-less landmarks
(one landmark in nine has a rule): 100, 1,000 and 10,000 nodes. The exhaustive search this
replaced took 15 s at 100 nodes and never finished at 10,000."""

from __future__ import annotations

from _common import Table, median_of


def grid(n: int):
    from workstation.graph import Landmark, LandmarkGraph

    nodes, edges = [], []
    for i in range(n):
        for j in range(n):
            rules = frozenset({"gyro"}) if i % 3 == 0 and j % 3 == 0 else frozenset()
            nodes.append(Landmark(f"n{i}_{j}", i * 5.0, j * 5.0, 0.0, rules, None))
            if i:
                edges += [(f"n{i}_{j}", f"n{i - 1}_{j}"), (f"n{i - 1}_{j}", f"n{i}_{j}")]
            if j:
                edges += [(f"n{i}_{j}", f"n{i}_{j - 1}"), (f"n{i}_{j - 1}", f"n{i}_{j}")]
    return LandmarkGraph(tuple(nodes), tuple(edges))


def run() -> Table:
    from workstation.pipeline.reach import Reach

    t = Table("Reachability on grid graphs (max_hops 3)")
    for n, rep in ((10, 5), (32, 3), (100, 1)):
        g = grid(n)
        med, _ = median_of(lambda g=g: Reach(g, 3), rep)
        t.add(f"{n * n:,} landmarks", med, "s", "{:,.2f}")
    return t


if __name__ == "__main__":
    run().print()
