"""A session header that loaded with a wrong value (issue #33): streams read from another
folder, one file read as two streams, a header that lost its `streams:` line and loaded as a
walk with no data, a stream file the header forgot. Each is refused naming session.yaml, or
said as a warning."""

import shutil

import pytest

from tests.conftest import REPO
from workstation.errors import InputError
from workstation.session import load_session

MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"

STREAMS = """streams:
  accelerometer: accelerometer.parquet
  gyroscope: gyroscope.parquet
  magnetometer: magnetometer.parquet
  wifi: wifi.parquet
  ground_truth: ground_truth.parquet
"""


def _folder(tmp_path, streams: str):
    folder = tmp_path / "walk"
    shutil.copytree(MS, folder)
    head = (folder / "session.yaml").read_text()
    (folder / "session.yaml").write_text(head.replace(STREAMS, streams))
    assert STREAMS in head
    return folder


@pytest.mark.parametrize(
    "streams, says",
    [
        ("", "lists no stream"),
        (STREAMS.replace("streams:\n", "").replace("  ", ""), "lists no stream"),  # line lost
        (STREAMS.replace("  accelerometer:", "  acceleration:"), "unknown stream 'acceleration'"),
        (STREAMS.replace("gyroscope: gyroscope", "gyroscope: accelerometer"),
         "accelerometer and gyroscope name the same file"),
        (STREAMS.replace("wifi: wifi.parquet", "wifi: ../other/wifi.parquet"),
         "is not the name of a file in the session folder"),
        (STREAMS.replace("wifi: wifi.parquet", "wifi: /tmp/wifi.parquet"),
         "is not the name of a file in the session folder"),
        (STREAMS.replace("wifi: wifi.parquet", "wifi: [a, b]"),
         "is not the name of a file"),
    ],
)  # fmt: skip
def test_a_wrong_stream_list_is_refused(tmp_path, streams, says):
    folder = _folder(tmp_path, streams)
    with pytest.raises(InputError, match=says) as e:
        load_session(folder)
    assert "session.yaml" in str(e.value)


def test_a_stream_file_the_header_forgot_is_said(tmp_path):
    folder = _folder(tmp_path, STREAMS.replace("  wifi: wifi.parquet\n", ""))
    s = load_session(folder)
    assert len(s.wifi) == 0
    assert any("wifi.parquet is in the folder but session.yaml does not list it" in w
               for w in s.metadata.warnings)  # fmt: skip
