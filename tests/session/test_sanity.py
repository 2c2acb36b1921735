"""Sessions that load are sane (issue #18): a corrupt timestamp is refused naming the stream,
non-finite samples are dropped with a warning, and the pipeline runs on whatever loads."""

import numpy as np
import pytest

from tests.conftest import gsd_lines
from workstation.errors import InputError
from workstation.graph import LandmarkGraph
from workstation.pipeline import Pipeline
from workstation.session import load_session


def _write(tmp_path, lines):
    p = tmp_path / "walk.txt"
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.parametrize("jump", ["1e9", "1e10", "1e300"])
def test_a_pressure_stamp_far_in_the_future_is_refused(tmp_path, jump):
    lines = gsd_lines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("PRES;"))
    f = lines[i].split(";")
    f[1] = jump
    lines[i] = ";".join(f)
    with pytest.raises(InputError, match="pressure|time"):
        load_session(_write(tmp_path, lines))


def test_a_logfile_nan_is_refused_with_its_line(tmp_path):
    lines = gsd_lines()
    k = next(k for k, ln in enumerate(lines) if ln.startswith("ACCE;"))
    f = lines[k].split(";")
    f[3] = "nan"
    lines[k] = ";".join(f)
    with pytest.raises(InputError, match=r"walk.txt:\d+: ACCE x: 'nan'"):
        load_session(_write(tmp_path, lines))


def test_non_finite_samples_in_a_session_folder_are_dropped_and_said(tmp_path):
    from dataclasses import replace

    from tests.conftest import REPO
    from workstation.session import Vector3, write_session

    s = load_session(REPO / "sample_sessions" / "office2f" / "normal")
    xyz = s.accelerometer.xyz.copy()
    xyz[5000:5010, 0] = np.nan
    bad = replace(s, accelerometer=Vector3(s.accelerometer.t, xyz))
    folder = write_session(bad, tmp_path / "walk")
    again = load_session(folder)
    assert np.isfinite(again.accelerometer.xyz).all()
    assert len(again.accelerometer) == len(s.accelerometer) - 10
    assert any("10 samples with non-finite values dropped" in w for w in again.warnings)
    r = Pipeline(
        again, LandmarkGraph.load(REPO / "sample_sessions/office2f/normal/graph.yaml")
    ).run()
    assert len(r.steps) > 400  # the walk still has its steps
