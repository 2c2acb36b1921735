"""Radio maps in object storage (issue #54 item 4): ``localize``, ``merge``, ``quality`` and
``plan`` read a map from an ``s3://`` URL as they read the same file on disk — a run's CSV, and
a campaign's merged map of one building (the prefix ``radiomap/building=NAME``) — against a
real S3-compatible server (moto's) the test starts on 127.0.0.1; a missing bucket or object,
no credentials and a cut object each give one line naming the URL, exit 2."""

from __future__ import annotations

import os

import pytest

from tests.conftest import REPO
from tests.s3 import local_s3, need_store, without_credentials
from workstation.cli import main

need_store()

WALK = REPO / "sample_sessions" / "office2f" / "normal"
HELD = REPO / "sample_sessions" / "office2f" / "heldout"


@pytest.fixture(scope="module")
def bucket(tmp_path_factory):
    """A bucket ``maps`` on a local S3 server holding a run's map (``run/radiomap.csv``) and a
    campaign-style merged map (``radiomap/building=office/floor=…/*.parquet``); the local
    copies beside them."""
    import fsspec
    import pyarrow.parquet as pq

    from workstation.export import map_table
    from workstation.fingerprints.localize import Fingerprints

    with local_s3():
        local = tmp_path_factory.mktemp("store")
        assert main(["run", str(WALK), "--graph", str(WALK / "graph.yaml"),
                     "--out", str(local / "run")]) == 0  # fmt: skip
        m = Fingerprints.read(local / "run" / "radiomap.csv")
        df = m.to_frame()
        df.insert(0, "building", "office")
        pq.write_to_dataset(map_table(df, m.frame, m.device), local / "radiomap",
                            partition_cols=["building", "floor"])  # fmt: skip
        fs = fsspec.filesystem("s3")
        fs.mkdir("maps")
        fs.put(str(local / "run" / "radiomap.csv"), "maps/run/radiomap.csv")
        fs.put(str(local / "radiomap") + "/", "maps/radiomap/", recursive=True)
        raw = (local / "run" / "radiomap.csv").read_bytes()
        fs.pipe("maps/cut.parquet", raw[: len(raw) // 3])  # a map cut short mid-upload
        yield local


def _said(capsys, argv) -> tuple[int, str, str]:
    code = main(argv)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("kind", ["run/radiomap.csv", "radiomap/building=office"])
def test_localize_on_a_map_in_the_store_gives_the_local_figures(bucket, capsys, kind):
    argv = ["localize", "--session", str(HELD), "--map"]
    code, here, _ = _said(capsys, [*argv, str(bucket / kind)])
    assert code == 0 and "mean" in here
    code, there, err = _said(capsys, [*argv, f"s3://maps/{kind}"])
    assert code == 0, err
    assert there.replace(f"s3://maps/{kind}", str(bucket / kind)) == here


def test_merge_quality_and_plan_read_a_map_from_the_store(bucket, capsys, tmp_path):
    code, out, err = _said(capsys, ["merge", "s3://maps/run/radiomap.csv",
                                    str(bucket / "run" / "radiomap.csv"),
                                    "-o", str(tmp_path / "m.csv")])  # fmt: skip
    assert code == 0, err
    assert (tmp_path / "m.csv").is_file()
    code, _, err = _said(capsys, ["quality", "--map", "s3://maps/radiomap/building=office",
                                  "--graph", str(WALK / "graph.yaml"), "--out", str(tmp_path / "q")])  # fmt: skip
    assert code == 0, err
    assert (tmp_path / "q" / "quality.json").is_file()


@pytest.mark.parametrize(
    "url, said",
    [
        ("s3://nobucket/radiomap.csv", "no such object, prefix or bucket"),
        ("s3://maps/run/none.csv", "no such object, prefix or bucket"),
        ("s3://maps/cut.parquet", "not a radio map"),
    ],
)
def test_bad_store_input_is_one_line_naming_the_url(bucket, capsys, url, said):
    code, out, err = _said(capsys, ["localize", "--session", str(HELD), "--map", url])
    assert code == 2
    assert err.strip().startswith(f"error: {url}") and said in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert os.environ["AWS_SECRET_ACCESS_KEY"] not in err


def test_no_credentials_is_said_without_a_traceback(bucket, capsys, monkeypatch):
    import s3fs

    without_credentials(monkeypatch)
    try:
        code, _, err = _said(capsys, ["localize", "--session", str(HELD), "--map",
                                      "s3://maps/run/radiomap.csv"])  # fmt: skip
    finally:
        s3fs.S3FileSystem.clear_instance_cache()
    assert code == 2 and err.startswith("error: s3://maps/run/radiomap.csv: ")
    assert "credentials" in err and len(err.strip().splitlines()) == 1


def test_an_object_whose_name_is_too_long_for_a_file_is_fetched_under_a_short_one(tmp_path):
    """Issue #67 item 6: a store object's key may be 1,024 bytes, a file's name 255: a walk
    named past that failed with "[Errno 36] File name too long". Fetched under a digest of its
    name that keeps its suffixes (the reader goes by them); a short name stays as it is."""
    from workstation.io.store import NAME_MAX, _local_name

    long = "w" * 300 + ".txt.gz"
    short = _local_name(long)
    assert len(short.encode()) <= NAME_MAX and short.endswith(".txt.gz")
    assert _local_name(long) == short and _local_name("x" * 301 + ".txt.gz") != short
    assert _local_name("walk.txt.gz") == "walk.txt.gz"
    (tmp_path / short).write_text("ok")  # a file the disk accepts


def test_get_bytes_and_a_listing_answer_as_the_objects_do(bucket, tmp_path):
    """The one-request reads a campaign in a store uses (issue #66): an object's bytes (None
    when absent, ``limit`` bytes at most) and every object under a prefix with what ``etag``
    says of each — on disk the same bytes, and no listing (the files are asked)."""
    from workstation.io.store import etag, get_bytes, listed, place

    raw = (bucket / "run" / "radiomap.csv").read_bytes()
    assert get_bytes(place("s3://maps/run/radiomap.csv")) == raw
    assert get_bytes(place("s3://maps/run/radiomap.csv"), limit=10) == raw[:10]
    assert get_bytes(place("s3://maps/run/nothing.csv")) is None
    assert get_bytes(bucket / "run" / "radiomap.csv") == raw
    assert get_bytes(tmp_path / "nothing") is None
    (tmp_path / "a folder").mkdir()
    assert get_bytes(tmp_path / "a folder") is None  # no file there, as is_file() says
    tags = listed(place("s3://maps/radiomap"))
    parts = sorted((bucket / "radiomap").rglob("*.parquet"))
    assert len(tags) == len(parts) >= 1
    for rel, tag in tags.items():
        assert tag == etag(place(f"s3://maps/radiomap/{rel}"))
    assert listed(place("s3://maps/no/such/prefix")) == {}
    assert listed(bucket / "radiomap") is None
