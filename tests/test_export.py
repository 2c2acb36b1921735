import json

import numpy as np
import pandas as pd
import pytest

from workstation.errors import WorkstationError
from workstation.export import write_radiomap
from workstation.fingerprints.localize import Fingerprints
from workstation.geo import LocalFrame


@pytest.fixture
def table():
    return pd.DataFrame(
        {
            "x": [1.0, 20.0],
            "y": [3.0, -4.0],
            "floor": [0.0, 1.0],
            "02:00:00:00:00:01": [-50.0, np.nan],
        }
    )


def test_geojson_is_lon_lat_when_the_map_has_a_frame(tmp_path, table):
    frame = LocalFrame(49.461, 11.111)
    write_radiomap(table, tmp_path / "m.geojson", frame)
    f = json.loads((tmp_path / "m.geojson").read_text())["features"]
    lon, lat = f[1]["geometry"]["coordinates"]
    x, y = frame.to_xy(lat, lon)
    assert (float(x), float(y)) == pytest.approx((20.0, -4.0), abs=1e-6)
    assert (
        f[0]["properties"]["rss"] == {"02:00:00:00:00:01": -50.0}
        and f[1]["properties"]["rss"] == {}
    )


def test_csv_and_parquet_round_trip(tmp_path, table):
    for name in ("m.csv", "m.parquet"):
        write_radiomap(table, tmp_path / name)
        back = Fingerprints.read(tmp_path / name)
        assert np.array_equal(back.rss, table[["02:00:00:00:00:01"]].to_numpy(), equal_nan=True)
        assert back.x.tolist() == [1.0, 20.0]


def test_unknown_format_is_refused(tmp_path, table):
    with pytest.raises(WorkstationError, match=r"must be one of \.csv, \.parquet, \.geojson"):
        write_radiomap(table, tmp_path / "m.xlsx")


def test_atomic_writes_use_the_umask_and_keep_a_files_mode(tmp_path):
    """Saved files are not private (0600) by accident: new ones follow the umask, a file saved
    over keeps its mode (issue #14)."""
    import os

    from workstation.io.atomic import atomic_write_text

    old = os.umask(0o022)
    try:
        p = tmp_path / "new.yaml"
        atomic_write_text(p, "a: 1\n")
        assert p.stat().st_mode & 0o777 == 0o644
        os.chmod(p, 0o640)
        atomic_write_text(p, "a: 2\n", backup=True)
        assert p.stat().st_mode & 0o777 == 0o640
    finally:
        os.umask(old)


def test_saving_through_a_symlink_keeps_the_link(tmp_path):
    from workstation.io.atomic import atomic_write_text

    real = tmp_path / "real.yaml"
    real.write_text("a: 1\n")
    link = tmp_path / "graph.yaml"
    link.symlink_to(real)
    atomic_write_text(link, "a: 2\n", backup=True)
    assert link.is_symlink() and real.read_text() == "a: 2\n"
    assert (tmp_path / "real.yaml.bak").read_text() == "a: 1\n"
    assert not list(tmp_path.glob(".*.tmp"))


def _pandas_csv(cols) -> str:
    return pd.DataFrame(cols).to_csv(index=False, float_format="%.6g")


def test_csv_is_written_as_pandas_writes_it_without_pandas():
    """`run` writes its tables without importing pandas (issue #17): the text is pandas'."""
    from workstation.export import _csv

    cols = {
        "t": np.array([0.1234567891, np.nan, 1e-7, -np.inf, 3.0, 123456789.0]),
        "n": np.arange(6),
        "ok": np.array([True, False, True, True, False, False]),
        "node": np.array(["A", None, "b,c", 'say "hi"', "", "line\nbreak"], dtype=object),
        "f32": np.linspace(0, 1, 6, dtype=np.float32),
    }
    assert _csv(cols) == _pandas_csv(cols)
    assert _csv(pd.DataFrame(cols)) == _pandas_csv(cols)


def test_run_tables_are_written_as_pandas_writes_them():
    from tests.conftest import REPO
    from workstation.export import (
        _csv,
        landmarks_columns,
        radiomap_columns,
        segments_columns,
        trajectory_columns,
    )
    from workstation.graph import LandmarkGraph
    from workstation.pipeline import run_pipeline
    from workstation.session import load_session

    walk = REPO / "sample_sessions" / "office2f" / "normal"
    r = run_pipeline(load_session(walk), LandmarkGraph.load(walk / "graph.yaml"))
    for columns in (trajectory_columns, landmarks_columns, segments_columns, radiomap_columns):
        cols = columns(r)
        assert _csv(cols) == _pandas_csv(cols), columns.__name__
