"""Kinds of radio map (workstation/fingerprints/kinds.py, issue #63): a kind added as its own
module and one registry line runs through merge, localize, quality and every export format; the
interpolated kind's kernel average against a simulated field's truth."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from workstation.cli import main
from workstation.fingerprints import kind_interpolated as ki
from workstation.fingerprints.kinds import KINDS, MapKind, build
from workstation.fingerprints.localize import Fingerprints

REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "tests" / "data" / "msilc"
WALKS = ("5dd9e7b29191710006b5705b", "5dd9e7c1c5b77e0006b17333")

#: the toy kind: every point of the walks' map moved 1 m east (here, in its own module)
TOY = MapKind("toy", "every point 1 m east", lambda m, graph: replace(m, x=m.x + 1.0))


@pytest.fixture(scope="module")
def walk_maps(tmp_path_factory) -> list[Path]:
    """Two bundled mall walks run: their radiomap.csv files."""
    out = tmp_path_factory.mktemp("kinds")
    maps = []
    for w in WALKS:
        assert main(["run", str(DATA / f"{w}.txt.gz"), "--graph", str(DATA / "site1_f1_graph.yaml"),
                     "--start", "first-fix", "--out", str(out / w)]) == 0  # fmt: skip
        maps.append(out / w / "radiomap.csv")
    return maps


def test_a_kind_added_by_one_registry_line_runs_through_every_command(
    walk_maps, tmp_path, monkeypatch, capsys
):
    monkeypatch.setitem(KINDS, "toy", "tests.test_map_kinds:TOY")  # the one line
    ins = [str(p) for p in walk_maps]
    assert main(["merge", *ins, "-o", str(tmp_path / "points.csv")]) == 0
    points = Fingerprints.read(tmp_path / "points.csv")
    for name in ("toy.csv", "toy.parquet", "toy.geojson"):  # merge writes each format
        assert main(["merge", *ins, "-o", str(tmp_path / name), "--kind", "toy"]) == 0
        toy = Fingerprints.read(tmp_path / name)
        assert toy.kind == "toy" and points.kind == "points"
        assert np.allclose(toy.x, points.x + 1.0) and np.allclose(toy.y, points.y)
        assert np.array_equal(np.isfinite(toy.aligned(points.bssids)), np.isfinite(points.rss))
    assert (tmp_path / "toy.csv").read_text().splitlines()[1] == "# kind: toy"
    capsys.readouterr()
    walk = str(DATA / f"{WALKS[0]}.txt.gz")
    assert main(["localize", "--map", str(tmp_path / "toy.parquet"), "--session", walk,
                 "-o", str(tmp_path / "est.csv")]) == 0  # fmt: skip
    assert "(a map of kind toy)" in capsys.readouterr().out
    assert main(["quality", "--map", str(tmp_path / "toy.geojson"), "--aps", "1",
                 "--out", str(tmp_path / "q")]) == 0  # fmt: skip
    assert (tmp_path / "q" / "quality.json").is_file()
    # a built map is not merged again: the file is named, and what to do
    capsys.readouterr()
    assert main(["merge", str(tmp_path / "toy.csv"), *ins, "-o", str(tmp_path / "x.csv")]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 'toy.csv'}: a map of kind toy" in err and "--kind" in err


def test_a_map_file_of_a_kind_nobody_registered_is_refused_with_its_name(walk_maps, tmp_path,
                                                                         capsys):  # fmt: skip
    text = walk_maps[0].read_text().splitlines()
    at = next(i for i, line in enumerate(text) if not line.startswith("#"))
    bad = tmp_path / "odd.csv"
    bad.write_text("\n".join([*text[:at], "# kind: hexagons", *text[at:]]) + "\n")
    walk = str(DATA / f"{WALKS[0]}.txt.gz")
    assert main(["localize", "--map", str(bad), "--session", walk]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and "kind 'hexagons'" in err and "Traceback" not in err


def _field(rng, n_aps=12):
    """A log-distance field of ``n_aps`` APs along a 60 × 4 m corridor: RSS at (x, y)."""
    ap = np.column_stack([rng.uniform(0, 60, n_aps), rng.uniform(-3, 3, n_aps)])

    def rss(x, y):
        d = np.hypot(x[:, None] - ap[None, :, 0], y[:, None] - ap[None, :, 1])
        v = -40.0 - 25.0 * np.log10(np.maximum(d, 1.0))
        return np.where(v >= -85.0, v, np.nan)

    return rss


@pytest.mark.parametrize("seed", range(4))
def test_interpolated_readings_follow_the_field_and_weigh_a_loose_point_little(seed):
    """Scans every ~1 m along a corridor, read with 3 dB noise: the virtual points' readings lie
    within 2.5 dB (RMS) of the true field where both hear the AP, closer than the raw scans'
    noise; one scan with the readings of a place 20 m away, given a 6 m σ, moves the virtual
    points around it by about a third or less of what it does with a 1 m σ."""
    rng = np.random.default_rng(seed)
    field = _field(rng)
    n = 70
    x, y = np.sort(rng.uniform(0, 60, n)), rng.uniform(-1.5, 1.5, n)
    rss = field(x, y) + rng.normal(0, 3.0, (n, 12))
    aps = np.array([f"ap{i}" for i in range(12)])
    fp = Fingerprints(x, y, np.zeros(n), aps, rss, sigma=np.full(n, 1.0))
    virt = build("interpolated", fp)
    assert virt.kind == "interpolated" and len(virt) > n
    truth = field(virt.x, virt.y)
    both = np.isfinite(truth) & np.isfinite(virt.rss)
    rms = float(np.sqrt(np.mean((virt.rss[both] - truth[both]) ** 2)))
    assert rms < 2.5, rms
    assert both.sum() >= 0.8 * np.isfinite(truth).sum()  # what is heard stays heard
    # the odd scan: the readings of x + 20 m, placed at x
    j = n // 2
    odd = rss.copy()
    odd[j] = field(np.array([x[j] + 20.0]), np.array([y[j]]))[0]

    def moved(sig_j: float) -> float:
        s = np.full(n, 1.0)
        s[j] = sig_j
        v = build("interpolated", replace(fp, rss=odd, sigma=s))
        near = np.hypot(v.x - x[j], v.y - y[j]) <= ki.LENGTH_M
        a, b = v.rss[near], virt.rss[near]
        ok = np.isfinite(a) & np.isfinite(b)
        return float(np.abs(a[ok] - b[ok]).mean())

    assert moved(6.0) < 0.35 * moved(1.0)


def test_virtual_points_stay_where_the_walks_went():
    """No virtual point farther than NEAR_M from a scan; each σ at least its distance to the
    nearest scan; floors kept apart."""
    rng = np.random.default_rng(7)
    x = np.concatenate([np.linspace(0, 30, 31), np.linspace(0, 30, 31)])
    y = np.concatenate([np.zeros(31), np.full(31, 20.0)])
    floor = np.concatenate([np.zeros(31), np.ones(31)])
    rss = rng.uniform(-80, -40, (62, 3))
    fp = Fingerprints(x, y, floor, np.array(["a", "b", "c"]), rss, sigma=np.full(62, 2.0))
    v = build("interpolated", fp)
    for f, yy in ((0.0, 0.0), (1.0, 20.0)):
        on = v.floor == f
        assert on.any() and np.abs(v.y[on] - yy).max() <= ki.NEAR_M + 1e-9
    d = np.hypot(v.x[:, None] - x[None], v.y[:, None] - y[None])
    d = np.where(v.floor[:, None] == floor[None], d, np.inf).min(axis=1)
    assert d.max() <= ki.NEAR_M + 1e-9 and (v.sigma >= d - 1e-9).all()
