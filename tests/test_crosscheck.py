"""The building's walks check each other (crosscheck.py, issue #49): on a simulated corridor with
a log-distance WiFi field, a walk placed 20 m off is flagged with about that distance and none
of the walks placed right is; a walk some of whose scans the others' map answers from afar is
not flagged; `merge` names a displaced real walk and leaves it out."""

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.fingerprints.localize import Fingerprints
from workstation.walks.crosscheck import DISAGREE_M, check_walks, disagreeing

APS = np.array([(x, 4.0) for x in range(0, 121, 8)], float)


def _walk(rng, shift: float = 0.0, n: int = 24, far_rows: int = 0) -> Fingerprints:
    """Scans along a 120-m corridor (y = 0): RSS −35 − 25 log10(d) + N(0, 3) dB; placed at the
    truth + N(0, 1 m), plus ``shift`` m along x; ``far_rows`` of its scans carry the fingerprint
    of a place 60 m away (stale or moved APs)."""
    x = np.sort(rng.uniform(10, 110, n))
    d = np.hypot(x[:, None] - APS[None, :, 0], APS[None, :, 1])
    rss = -35 - 25 * np.log10(d) + rng.normal(0, 3, d.shape)
    if far_rows:
        src = np.clip(x[-far_rows:] + np.where(x[-far_rows:] > 60, -60, 60), 0, 120)
        dd = np.hypot(src[:, None] - APS[None, :, 0], APS[None, :, 1])
        rss[-far_rows:] = -35 - 25 * np.log10(dd) + rng.normal(0, 3, dd.shape)
    px = x + rng.normal(0, 1, n) + shift
    py = rng.normal(0, 1, n)
    bssids = np.array([f"ap{i:02d}" for i in range(len(APS))])
    return Fingerprints(px, py, np.zeros(n), bssids, rss)


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_a_walk_placed_20_m_off_is_flagged_and_the_right_ones_are_not(seed):
    rng = np.random.default_rng(seed)
    maps = {f"w{i}": _walk(rng) for i in range(8)}
    maps["off"] = _walk(rng, shift=20.0)
    checks = check_walks(maps)
    bad = disagreeing(checks)
    assert list(bad) == ["off"]
    assert 14.0 <= bad["off"].offset_m <= 26.0
    assert bad["off"].dx < 0  # the others put its scans back west, where they were taken
    assert "disagrees with the building's other walks by" in bad["off"].words()
    assert all(checks[n].offset_m < DISAGREE_M for n in maps if n != "off")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_walk_placed_right_is_not_flagged_for_scans_answered_from_afar(seed):
    """A third of a good walk's scans look like a place 60 m away: its median displacement may
    be large, but most of its scans agree with where it put them — no flag."""
    rng = np.random.default_rng(seed)
    maps = {f"w{i}": _walk(rng) for i in range(8)}
    maps["stale"] = _walk(rng, far_rows=8)
    assert "stale" not in disagreeing(check_walks(maps))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_walk_where_nobody_else_walked_is_not_flagged(seed):
    """The others walked x 10–60 m; one walk, placed right, covers 75–115 m: the others' map
    answers its scans from 60 m (its nearest place), far from where it put them — but it does
    not recognise those fingerprints as it recognises its own walks' scans: nothing to check."""
    rng = np.random.default_rng(seed)
    maps = {}
    for i in range(8):
        w = _walk(rng)
        keep = w.x < 60
        maps[f"w{i}"] = w.subset(keep)
    far = _walk(rng)
    maps["new"] = far.subset(far.x > 75)
    checks = check_walks(maps)
    assert "new" not in disagreeing(checks)


def test_too_few_walks_or_points_check_nothing():
    rng = np.random.default_rng(0)
    assert check_walks({"a": _walk(rng)}) == {}
    small = {"a": _walk(rng), "b": _walk(rng, n=3), "c": _walk(rng)}
    assert set(check_walks(small)) == {"a", "c"}


def test_merge_names_a_displaced_real_walk_and_leaves_it_out(tmp_path, capsys):
    """The bundled mall walks run from their first fix, one of them given a start 20 m from
    where it began (a surveyor's slip): merge says which walk disagrees and by how much, and
    merges the others; --include-disagreeing keeps it."""
    import pandas as pd

    data = REPO / "tests" / "data" / "msilc"
    graph = data / "site1_f1_graph.yaml"
    maps, slip = [], "5dd9e7c4c5b77e0006b17335"
    for w in sorted(data.glob("*.gz")):
        out = tmp_path / w.name.split(".")[0]
        start = "L142" if w.name.startswith(slip) else "first-fix"
        if main(["run", str(w), "--graph", str(graph), "--start", start, "--out", str(out)]) == 0:
            maps.append(out / "radiomap.csv")
    moved = tmp_path / slip / "radiomap.csv"
    assert len(maps) >= 6 and moved in maps
    capsys.readouterr()
    merged = tmp_path / "merged.csv"
    assert main(["merge", *map(str, maps), "-o", str(merged)]) == 0
    said = capsys.readouterr().out
    assert f"{moved}: disagrees with the building's other walks by" in said
    assert said.count("disagrees with") == 1 and "left out" in said and "what to do" in said
    n = len(pd.read_csv(merged, comment="#"))
    assert main(["merge", *map(str, maps), "-o", str(merged), "--include-disagreeing"]) == 0
    assert "kept as asked" in capsys.readouterr().out
    assert len(pd.read_csv(merged, comment="#")) > n
