"""Nothing a user exported is lost (issue #50 item 1): a radio map written as CSV, Parquet or
GeoJSON reads back with the same points, readings, frame, phone model and points on standby,
and every command gives the same result on each (a Parquet export once lost the frame, and
localize reported 72.77 m instead of 1.42 m; GeoJSON carried a fake access point `standby`
and merge could not read it)."""

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.export import FORMATS, radiomap_table, write_radiomap
from workstation.fingerprints.localize import Fingerprints
from workstation.geo import LocalFrame
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

DATA = REPO / "tests" / "data" / "msilc"
WALK = DATA / "5dd9e7b29191710006b5705b.txt.gz"  # a walk with points on standby


@pytest.fixture(scope="module")
def run():
    g = LandmarkGraph.load(DATA / "site1_f1_graph.yaml")
    s = load_session(WALK).in_frame(g.frame)
    r = Pipeline(s, g, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, g)}))
    return r.run()


def _same(a: Fingerprints, b: Fingerprints) -> None:
    assert np.allclose(a.x, b.x, atol=1e-4) and np.allclose(a.y, b.y, atol=1e-4)
    assert np.array_equal(a.floor, b.floor)
    assert sorted(a.bssids.tolist()) == sorted(b.bssids.tolist())
    order = np.argsort(b.bssids)[np.searchsorted(np.sort(b.bssids), a.bssids)]
    assert np.allclose(a.rss, b.rss[:, order], equal_nan=True, atol=1e-3)
    assert a.frame == b.frame and a.device == b.device
    assert np.array_equal(a.on_standby, b.on_standby)


@pytest.mark.parametrize("fmt", sorted(FORMATS))
@pytest.mark.parametrize("frame", [None, LocalFrame(49.4611, 11.1103)])
def test_every_format_reads_back_whole(run, tmp_path, fmt, frame):
    assert run.radiomap.held_for_sigma.any()  # the walk has points on standby to keep
    path = write_radiomap(radiomap_table(run), tmp_path / f"m.{fmt}", frame, device="OPPO X")
    back = Fingerprints.read(path)
    csv = Fingerprints.read(write_radiomap(radiomap_table(run), tmp_path / "ref.csv", frame,
                                           device="OPPO X"))  # fmt: skip
    _same(back, csv)
    assert back.frame == frame and back.device == "OPPO X"
    assert "standby" not in back.bssids.tolist()  # never an access point
    # and it writes again into every format unchanged
    for other in sorted(FORMATS):
        again = Fingerprints.read(write_radiomap(back.to_frame(), tmp_path / f"again.{other}",
                                                 back.frame, device=back.device))  # fmt: skip
        _same(again, back)


def test_every_command_gives_the_same_result_on_every_format(run, tmp_path, capsys):
    paths = [write_radiomap(radiomap_table(run), tmp_path / f"m.{f}", None, device="OPPO PBCM10")
             for f in sorted(FORMATS)]  # fmt: skip
    query = DATA / "5dd9e7c1c5b77e0006b17333.txt.gz"
    said = []
    for p in paths:
        capsys.readouterr()
        assert main(["localize", "--map", str(p), "--session", str(query)]) == 0
        said.append(capsys.readouterr().out.splitlines()[1:])  # (the first line names the map)
    assert said[0] == said[1] == said[2]
    merged = []
    for p in paths:
        out = tmp_path / f"merged_{p.suffix[1:]}.csv"
        assert main(["merge", str(p), str(paths[0]), "-o", str(out)]) == 0
        merged.append(Fingerprints.read(out))
    _same(merged[0], merged[1])
    _same(merged[0], merged[2])


def test_a_campaigns_map_keeps_its_frame_and_phone_model(tmp_path):
    """The partitioned map a campaign writes (radiomap/building=NAME) carries the frame and the
    phone model in every part, and reads back with them."""
    import pandas as pd
    import pyarrow.parquet as pq

    from workstation.export import map_table

    df = pd.DataFrame({"building": ["b"] * 3, "floor": [0.0, 0.0, 1.0], "x": [1.0, 2.0, 3.0],
                       "y": [0.0, 1.0, 2.0], "aa:bb": [-50.0, np.nan, -70.0]})  # fmt: skip
    frame = LocalFrame(40.4, -3.7)
    pq.write_to_dataset(map_table(df, frame, "Pixel 7"), tmp_path, partition_cols=["building", "floor"])
    m = Fingerprints.read(tmp_path / "building=b")
    assert m.frame == frame and m.device == "Pixel 7" and len(m) == 3
    assert sorted(m.floor.tolist()) == [0.0, 0.0, 1.0]


@pytest.mark.parametrize(
    "text, said",
    [
        ("{", "not JSON"),
        ('{"type": "Feature"}', "not a GeoJSON FeatureCollection"),
        ('{"type": "FeatureCollection", "features": 3}', "features are not a list"),
        ('{"type": "FeatureCollection", "features": [{"geometry": null}]}', "no properties"),
        ('{"type": "FeatureCollection", "features": [{"properties": {"floor": 0}}]}',
         "no point coordinates"),
        ('{"type": "FeatureCollection", "workstation": {"frame": {"origin_lat": "x"}}, '
         '"features": []}', "frame is not origin_lat/origin_lon numbers"),
    ],
)  # fmt: skip
def test_a_bad_geojson_map_is_one_clear_line(tmp_path, capsys, text, said):
    p = tmp_path / "bad.geojson"
    p.write_text(text)
    assert main(["merge", str(p), "-o", str(tmp_path / "m.csv")]) == 2
    err = capsys.readouterr().err
    assert str(p) in err and said in err and "Traceback" not in err


@pytest.mark.parametrize(
    "text, said, line",
    [
        # one extra comma on the first data row once moved every column by one, exit 0
        ("# frame origin_lat=1 origin_lon=2\nx,y,floor,t,ap1\n1,2,0,5,,-50\n3,4,0,6,-60\n",
         "6 fields, but the header names 5", 3),
        ("x,y,floor,ap1\n1,2,0,-50\n1,2,0," + "," * 100_000 + "\n",
         "100,004 fields, but the header names 4", 3),
        ("# frame origin_lat=1 origin_lon=2\n# device: X", "no header line", 3),
        ("x,y,,ap1\n1,2,0,-50\n", "column 3 of the header has no name", 1),
    ],
)  # fmt: skip
def test_a_radio_map_row_that_does_not_fit_its_header_is_named(tmp_path, capsys, text, said, line):
    """Issue #55 items 2, 3 and 7: each is one line naming the file and line, for localize
    and merge alike — never a shifted map, a MemoryError or an IndexError."""
    p = tmp_path / "map.csv"
    p.write_text(text)
    for args in (["merge", str(p), "-o", str(tmp_path / "m.csv")],
                 ["localize", "--map", str(p), "--session", str(WALK)]):  # fmt: skip
        assert main(args) == 2
        err = capsys.readouterr().err
        assert f"{p}:{line}:" in err and said in err and "Traceback" not in err
