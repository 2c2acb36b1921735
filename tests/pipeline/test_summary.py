"""summary.json, typed (issue #52): a run's :class:`Summary` written and read back is the same
summary; the verdict read from the file is the verdict the run gave; the schema is versioned."""

import json

import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.graph import LandmarkGraph
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.pipeline.summary import SCHEMA, Summary
from workstation.pipeline.verdict import quarantine
from workstation.session import load_session

OFFICE = REPO / "sample_sessions" / "office2f" / "normal"
MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"


@pytest.mark.parametrize("walk, start", [(OFFICE, None), (MS, "infer"), (MS, "first-fix")])
def test_a_summary_reads_back_as_written(walk, start):
    s, g = load_session(walk), LandmarkGraph.load(walk / "graph.yaml")
    p = Pipeline(s, g)
    if start == "first-fix":
        p = Pipeline(s, g, p.params.updated(**{"pdr.start_node": resolve_start(start, s, g)}))
    summ = p.run().summary(p.session, g)
    text = json.dumps(summ.to_json())
    back = Summary.from_json(json.loads(text))
    assert back.to_json() == json.loads(text)
    assert back.reasons == summ.reasons and back.inferred == summ.inferred
    assert [q.reason for q in quarantine(back)] == list(summ.reasons)  # the verdict, re-derived
    assert json.loads(text)["schema"] == SCHEMA


def test_run_writes_the_summary_the_reader_takes(tmp_path):
    out = tmp_path / "run"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out", str(out)]) == 0
    d = json.loads((out / "summary.json").read_text())
    s = Summary.from_json(d)
    assert s.to_json() == d and not s.quarantined and s.reference_points == d["reference_points"]
    assert s.figure("trajectory_error_mean_m") == d["trajectory_error_mean_m"]  # ground truth


def test_an_unversioned_summary_reads_and_a_newer_one_is_refused():
    old = {"steps": 40, "landmarks_matched": 2, "reference_points": 5, "quarantine": [
        {"reason": "end_far", "detail": "…", "what_to_do": "…"}]}  # fmt: skip
    assert Summary.from_json(old).reasons == ("end_far",)  # written before the schema key
    with pytest.raises(ValueError, match="schema"):
        Summary.from_json({**old, "schema": SCHEMA + 1})
