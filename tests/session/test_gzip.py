"""Compressed walks: every format reads gzipped as it reads plain, errors still name the file
and line, and a broken or oversized archive is a typed error."""

import gzip
import shutil

import numpy as np
import pytest

from tests.conftest import REPO, gsd_lines
from workstation.errors import InputError
from workstation.session import _parse, load_session

MSILC_GZ = REPO / "tests" / "data" / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"


def _same(a, b):
    assert np.array_equal(a.accelerometer.t, b.accelerometer.t)
    assert np.array_equal(a.accelerometer.xyz, b.accelerometer.xyz)
    assert np.array_equal(a.ground_truth.x, b.ground_truth.x)
    assert a.wifi.n_scans == b.wifi.n_scans and len(a.wifi) == len(b.wifi)


def test_gzipped_path_file_reads_as_the_plain_one(tmp_path):
    plain = tmp_path / "walk.txt"
    with gzip.open(MSILC_GZ) as f, plain.open("wb") as out:
        shutil.copyfileobj(f, out)
    _same(load_session(MSILC_GZ), load_session(plain))


def test_gzipped_getsensordata_reads_as_the_plain_one(tmp_path):
    text = "\n".join(gsd_lines()) + "\n"
    plain, packed = tmp_path / "log.txt", tmp_path / "log.txt.gz"
    plain.write_text(text)
    packed.write_bytes(gzip.compress(text.encode()))
    _same(load_session(packed), load_session(plain))


def test_error_in_a_gzipped_file_names_file_and_line(tmp_path):
    lines = gsd_lines()
    lines[10] = "ACCE;1.0;1000.2;0.1;abc;9.8;3"
    packed = tmp_path / "bad.txt.gz"
    packed.write_bytes(gzip.compress(("\n".join(lines) + "\n").encode()))
    with pytest.raises(InputError) as e:
        load_session(packed)
    assert "bad.txt.gz" in str(e.value) and ":11" in str(e.value)


def test_truncated_and_corrupt_archives_are_typed_errors(tmp_path):
    data = MSILC_GZ.read_bytes()
    cut = tmp_path / "cut.txt.gz"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="truncated"):
        load_session(cut)
    bad = tmp_path / "bad.txt.gz"
    bad.write_bytes(data[:20] + bytes(200) + data[220:])
    with pytest.raises(InputError, match="gzip|truncated|record|format"):
        load_session(bad)


def test_a_decompression_bomb_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.setattr(_parse, "MAX_UNPACKED_BYTES", 1 << 16)
    p = tmp_path / "bomb.txt.gz"
    p.write_bytes(gzip.compress(("\n".join(gsd_lines(seconds=40)) + "\n").encode()))
    with pytest.raises(InputError, match="unpacks to more than"):
        load_session(p)
