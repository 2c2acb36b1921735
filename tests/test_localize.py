import numpy as np
import pytest
from scipy.spatial.distance import cdist

from tests.conftest import REPO, UJI, need
from workstation.cli import main
from workstation.export import write_radiomap
from workstation.fingerprints.localize import (
    Fingerprints,
    Metric,
    errors,
    localize,
    nearest,
    positive,
)
from workstation.geo import LocalFrame


def test_positive_representation_eq21():
    rss = np.array([[-50.0, np.nan, -95.0, -80.0]])
    out = positive(rss, tau=-90.0, rss_min=-101.0)
    assert out.tolist() == [[51.0, 0.0, 0.0, 21.0]]


@pytest.mark.parametrize(
    "metric, scipy_name", [(Metric.EUCLIDEAN, "euclidean"), (Metric.SORENSEN, "braycurtis")]
)
def test_distances_match_scipy(metric, scipy_name):
    rng = np.random.default_rng(0)
    ref = np.where(rng.random((300, 40)) < 0.3, rng.uniform(1, 60, (300, 40)), 0.0)
    qry = np.where(rng.random((50, 40)) < 0.3, rng.uniform(1, 60, (50, 40)), 0.0)
    idx, dist = nearest(ref, qry, metric, k=3)
    full = cdist(qry, ref, scipy_name)
    assert np.allclose(dist, np.sort(full, axis=1)[:, :3])
    assert np.array_equal(idx[:, 0], full.argmin(axis=1))


@pytest.mark.parametrize("n, aps, density", [(300, 40, 0.3), (6000, 400, 0.01)])
@pytest.mark.parametrize("metric", ["euclidean", "sorensen"])
@pytest.mark.parametrize("k", [1, 4])
@pytest.mark.parametrize("step", [1.0, 0.5])
def test_exact_k_nearest_with_ties_to_the_lower_index(n, aps, density, metric, k, step):
    """The index's answer is the brute force's, ties to the lower index — on a map whose query
    lists cover it (one pass over every point) and on a sparse one (only the points touched);
    whole-dB readings (the byte / int32 path) and half-dB ones (float64). Few distinct
    readings make ties common."""
    from workstation.fingerprints.nn import DENSE_RATIO, InvertedIndex

    rng = np.random.default_rng(1)
    ref = np.where(rng.random((n, aps)) < density, rng.integers(1, 8, (n, aps)), 0) * step
    qry = np.where(rng.random((60, aps)) < 3 * density, rng.integers(1, 8, (60, aps)), 0) * step
    work = (qry > 0).astype(float) @ (ref > 0).sum(axis=0)
    dense = n <= DENSE_RATIO * work
    assert dense.all() if n == 300 else not dense.any()  # both kernels are exercised
    index = InvertedIndex.build(ref)
    assert (index.col_val.dtype == np.uint8) == (step == 1.0)
    idx, dist = index.search(qry, metric, k)
    full = cdist(qry, ref, "euclidean" if metric == "euclidean" else "braycurtis")
    full = np.nan_to_num(full, nan=0.0)  # two empty fingerprints: distance 0
    order = np.lexsort((np.broadcast_to(np.arange(n), full.shape), full), axis=1)[:, :k]
    assert np.allclose(dist, np.take_along_axis(full, order, axis=1))
    assert np.array_equal(idx, order)


@pytest.mark.parametrize("n, aps, density", [(300, 40, 0.3), (6000, 400, 0.01)])
@pytest.mark.parametrize("k", [1, 4])
def test_search_without_some_points_is_the_search_of_the_others(n, aps, density, k):
    """Leave-one-walk-out's shared index: the k nearest with the points lo:hi left out are the
    brute force's over the other points (ties to the lower index), on both kernels, also where
    the queries hear APs that only the points left out heard."""
    from workstation.fingerprints.nn import InvertedIndex

    rng = np.random.default_rng(2)
    ref = np.where(rng.random((n, aps)) < density, rng.integers(1, 8, (n, aps)), 0).astype(float)
    lo, hi = n // 3, n // 3 + n // 10
    ref[lo:hi, :3] = 5.0  # three APs only the points left out hear …
    ref[:lo, :3] = ref[hi:, :3] = 0.0
    qry = np.where(rng.random((60, aps)) < 3 * density, rng.integers(1, 8, (60, aps)), 0)
    qry[:, :3] = 4  # … and every query hears them
    idx, _ = InvertedIndex.build(ref).search_without(qry, k, lo, hi)
    keep = np.r_[0:lo, hi:n]
    full = cdist(qry, ref[keep], "euclidean")
    order = np.lexsort((np.broadcast_to(np.arange(keep.size), full.shape), full), axis=1)[:, :k]
    assert np.array_equal(idx, keep[order])


def _fp(xs, floors, rss, bssids=("a", "b", "c")):
    n = len(xs)
    return Fingerprints(
        np.array(xs, float),
        np.zeros(n),
        np.array(floors, float),
        np.array(bssids),
        np.array(rss, float),
    )


def test_knn_floor_and_error_counted_where_the_floor_is_right():
    m = _fp([0, 10, 20], [0, 0, 1], [[-40, -80, np.nan], [-80, -40, np.nan], [np.nan, np.nan, -40]])
    q = _fp([1, 11, 25], [0, 1, 1], [[-41, -79, np.nan], [-79, -41, np.nan], [np.nan, np.nan, -42]])
    est = localize(m, q, Metric.EUCLIDEAN, k=1)
    assert est.x.tolist() == [0, 10, 20] and est.floor.tolist() == [0, 0, 1]
    e = errors(est, q)
    assert e["floor_accuracy"] == pytest.approx(2 / 3, abs=1e-4)
    assert e["mean_m"] == pytest.approx((1 + 5) / 2)  # the wrong-floor query is not counted


def test_merge_aligns_access_points(tmp_path):
    a = _fp([0], [0], [[-40, -50]], bssids=("a", "b"))
    b = _fp([5], [0], [[-60, -70]], bssids=("b", "c"))
    m = Fingerprints.merge([a, b])
    assert m.bssids.tolist() == ["a", "b", "c"]
    assert np.array_equal(m.rss, [[-40, -50, np.nan], [np.nan, -60, -70]], equal_nan=True)
    frame = LocalFrame(49.461, 11.111)
    p = tmp_path / "m.csv"
    write_radiomap(Fingerprints(m.x, m.y, m.floor, m.bssids, m.rss, frame).to_frame(), p, frame)
    back = Fingerprints.read(p)
    assert back.frame == frame and np.array_equal(back.rss, m.rss, equal_nan=True)


def test_localize_command_on_the_simulated_office(tmp_path, capsys):
    walk = REPO / "sample_sessions" / "office2f"
    out = tmp_path / "run"
    assert (
        main(
            [
                "run",
                str(walk / "normal"),
                "--graph",
                str(walk / "normal" / "graph.yaml"),
                "--out",
                str(out),
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert (
        main(["localize", "--map", str(out / "radiomap.csv"), "--session", str(walk / "heldout")])
        == 0
    )
    text = capsys.readouterr().out
    assert float(text.split("floor accuracy")[1].split("%")[0]) >= 90.0
    mean = float(text.split("mean ")[1].split(" m")[0])
    assert mean < 5.0
    assert (
        main(
            [
                "merge",
                str(out / "radiomap.csv"),
                str(out / "radiomap.csv"),
                "-o",
                str(tmp_path / "m.csv"),
            ]
        )
        == 0
    )
    assert "reference points" in capsys.readouterr().out


@pytest.mark.shared_data
def test_ujiindoorloc_plain_1nn_lands_near_the_published_figure():
    from workstation.fingerprints.uji import read_uji

    train, val = read_uji(need(UJI / "UJIIndoorLoc.zip"))
    assert len(train) == 19937 and len(val) == 1111
    est = localize(train, val, Metric.EUCLIDEAN, k=1, tau=-1e9, rss_min=-105.0)
    e = errors(est, val)
    assert 7.4 <= e["mean_m"] <= 8.5  # published ≈ 7.9 m
    assert 0.88 <= e["floor_accuracy"] <= 0.92  # published ≈ 90 %
    better = errors(localize(train, val, Metric.SORENSEN, k=3, tau=-90.0), val)
    assert better["mean_m"] < e["mean_m"]


def test_a_radio_map_csv_is_read_as_written_or_refused_with_its_line(tmp_path):
    """Issue #33: an `accepted` of 'Tru' silently dropped rows, a '#' inside a row lost the rest
    of its readings, a repeated AP column became 'ap.1', a frame origin of NaN was accepted."""
    from workstation.errors import InputError

    def read(text):
        p = tmp_path / "m.csv"
        p.write_text(text)
        return Fingerprints.read(p)

    m = read("# device: X\nx,y,floor,accepted,a#1,b\n1,2,0,True,-60,-70\n3,4,0,false,-61,\n")
    assert len(m) == 1 and list(m.bssids) == ["a#1", "b"] and m.device == "X"
    m = read("x,y,floor,ssid#,b\n1,2,0,-50,-70\n")  # '#' is data inside a row
    assert list(m.bssids) == ["ssid#", "b"] and m.rss[0, 1] == -70
    for text, msg, line in (
        ("x,y,floor,accepted,a\n1,2,0,True,-60\n3,4,0,Tru,-61\n", "not 'Tru'", 3),
        ("x,y,floor,a,a\n1,2,0,-60,-61\n", "'a' appears twice", 1),
        ("# frame origin_lat=nan origin_lon=11\nx,y,floor,a\n1,2,0,-60\n", "latitude", 1),
        ("x,y,floor," + ",".join(f"ap{i}" for i in range(100_001)) + "\n", "columns", 1),
    ):
        with pytest.raises(InputError, match=msg) as e:
            read(text)
        assert e.value.line == line, (text, e.value.line)


OFFICE = REPO / "sample_sessions" / "office2f"


@pytest.fixture(scope="module")
def office_map(tmp_path_factory):
    out = tmp_path_factory.mktemp("office") / "normal"
    assert main(["run", str(OFFICE / "normal"), "--graph", str(OFFICE / "normal" / "graph.yaml"),
                 "--out", str(out)]) == 0  # fmt: skip
    return out / "radiomap.csv"


def test_a_walk_without_ground_truth_is_localized_scan_by_scan(office_map, tmp_path, capsys):
    """Issue #64 item 2: localize needed the walk's ground truth and printed only errors. A walk
    nobody measured (the held-out walk with its ground truth removed) gets one row per scan."""
    import shutil

    import pandas as pd

    walk = tmp_path / "unmeasured"
    shutil.copytree(OFFICE / "heldout", walk)
    (walk / "ground_truth.parquet").unlink()
    yml = (walk / "session.yaml").read_text().splitlines()
    (walk / "session.yaml").write_text("\n".join(ln for ln in yml if "ground_truth" not in ln))
    capsys.readouterr()
    est = tmp_path / "est.csv"
    assert main(["localize", "--map", str(office_map), "--session", str(walk), "-o", str(est)]) == 0
    said = capsys.readouterr().out
    assert "no ground truth in the walk: estimates only" in said and "error" not in said
    df = pd.read_csv(est)
    from workstation.session import load_session

    n = load_session(walk).wifi.matrix()[0].size
    assert len(df) == n and f"{n} scans of {walk}, {n} localized" in said
    assert {"t", "x", "y", "floor", "match_distance", "aps_heard", "aps_known"} <= set(df.columns)
    assert "error_m" not in df.columns and df[["x", "y"]].notna().all().all()
    assert (df["aps_known"] <= df["aps_heard"]).all() and (df["aps_known"] > 0).all()


def test_with_ground_truth_errors_per_scan_and_every_scan_not_used_counted(office_map, tmp_path,
                                                                        capsys):  # fmt: skip
    """With ground truth the rows carry the truth and the error, and the printed mean is theirs;
    a map that knows only two of the walk's APs leaves the scans hearing neither out, counted
    with why; every format holds the same rows."""
    import json

    import pandas as pd

    capsys.readouterr()
    paths = [tmp_path / f"est.{s}" for s in ("csv", "parquet", "geojson")]
    for p in paths:
        assert main(["localize", "--map", str(office_map), "--session", str(OFFICE / "heldout"),
                     "-o", str(p)]) == 0  # fmt: skip
    said = capsys.readouterr().out
    df = pd.read_csv(paths[0])
    assert np.isfinite(df["error_m"]).all()
    mean = float(said.split("error (floor right): mean ")[1].split(" m")[0])
    right = df["floor"] == df["true_floor"]
    assert abs(df["error_m"][right].mean() - mean) < 0.006
    pq = pd.read_parquet(paths[1])
    assert np.allclose(pq["x"], df["x"]) and np.allclose(pq["error_m"], df["error_m"])
    feats = json.loads(paths[2].read_text())["features"]
    assert len(feats) == len(df) and feats[0]["properties"]["aps_known"] == df["aps_known"][0]

    fp = Fingerprints.read(office_map)  # the map with two of its APs left
    heard = np.isfinite(fp.rss).sum(axis=0)
    keep = np.argsort(-heard)[:2]
    small = Fingerprints(fp.x, fp.y, fp.floor, fp.bssids[keep], fp.rss[:, keep], fp.frame)
    write_radiomap(small.to_frame(), tmp_path / "small.csv", fp.frame)
    out = tmp_path / "small_est.csv"
    assert main(["localize", "--map", str(tmp_path / "small.csv"), "--session",
                 str(OFFICE / "heldout"), "-o", str(out), "--force"]) == 0  # fmt: skip
    said = capsys.readouterr().out
    d = pd.read_csv(out)
    gone = int((d["aps_known"] == 0).sum())
    assert gone > 0 and f"  {gone} no AP the map knows: not localized" in said
    assert d["x"][d["aps_known"] == 0].isna().all() and not d["localized"][d["aps_known"] == 0].any()


@pytest.mark.parametrize("bad", [["--k", "0"], ["--k", "-3"], ["--k", "x"], ["--tau", "20"],
                                 ["--tau", "nan"]])  # fmt: skip
def test_impossible_k_and_tau_are_refused_in_one_line(bad, capsys):
    with pytest.raises(SystemExit) as e:
        main(["localize", "--map", "m.csv", "--session", "w", *bad])
    assert e.value.code == 2
    assert bad[0] in capsys.readouterr().err


def test_k_beyond_the_map_is_refused(office_map, capsys):
    assert main(["localize", "--map", str(office_map), "--session", str(OFFICE / "heldout"),
                 "--k", "100000"]) == 2  # fmt: skip
    assert "--k 100000: the map has" in capsys.readouterr().err


def test_view_with_a_map_draws_every_scan_localized_beside_the_track(office_map, tmp_path, capsys):
    """view --map: each localized scan a point on its floor (the map's WiFi alone), with a line
    to where the walk's track was at that scan; the recording path on a line of its own."""
    from rerun.chunk import RrdReader

    rrd = tmp_path / "v.rrd"
    assert main(["view", str(OFFICE / "heldout"), "--graph", str(OFFICE / "heldout" / "graph.yaml"),
                 "--map", str(office_map), "--save", str(rrd)]) == 0  # fmt: skip
    said = capsys.readouterr().out.splitlines()
    assert said[-1] == f"saved {rrd} — open it with: " + said[-1].split("open it with: ")[1]
    assert said[-1].endswith(str(rrd))  # no colon glued to the path
    n = {}
    for ch in RrdReader(rrd).stream():
        if ch.entity_path.endswith("/localized/estimates"):
            b = ch.to_record_batch()
            col = next(c for c in b.schema.names if c.endswith("positions"))
            n[ch.entity_path] = sum(len(v) for v in b.column(col).to_pylist())
    from workstation.session import load_session

    scans = load_session(OFFICE / "heldout").wifi.matrix()[0].size
    assert len(n) == 2 and sum(n.values()) == scans  # both floors, every scan
    assert f"{scans} of its {scans} scans localized on the map" in "\n".join(said)
