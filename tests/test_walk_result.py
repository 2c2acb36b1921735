"""A campaign walk's result (campaign/walk_result.py): the summary.json files the campaign has
always written read as records, written back unchanged, and typed where the passes read them."""

import json

import pytest

from workstation.campaign.records import Records, summary_text
from workstation.campaign.walk_result import SUMMARY_KEYS, WalkResult
from workstation.pipeline.start import HandedStart

FIGURES = {k: None for k in SUMMARY_KEYS} | {
    "steps": 58, "start_node": "L27", "end_node": None, "end_how": "last_match",
    "reference_points": 14,
    "quarantine": [{"reason": "start_ambiguous", "detail": "L27 or L21", "what_to_do": "give it"}],
    "start_after": {"walk_before": "w0", "gap_s": 4.1, "ended_at": [80.5, 95.25, 0.0],
                    "reach_m": 9.5, "landmarks_in_reach": 3, "any_floor": False},
}  # fmt: skip

# as the campaign wrote them before the record: a walk run with its start handed over, one that
# ran again from the start its group chose, and one whose file could not be read
HANDED = {
    "key": "mall/w1", "building": "mall", "walk": "w1.txt.gz", "digest": "d1|after:mall/w0:x",
    "summary": FIGURES, "device": "Pixel", "clock": [1574300000.5, 1574300060.0],
    "ended": [80.5, 95.25, 0.0, 1.3], "floor_name": "F1", "status": "ok", "seconds": 0.12,
    "start_inference": {"candidates": [["L27", 0.0], ["L21", 1.04]],
                        "stand": [["aa:bb", "cc:dd"], [-61.5, -70.25]], "tau_dbm": -90.0},
    "start_after": FIGURES["start_after"],
}  # fmt: skip
SHARED = {
    "key": "mall/w2", "building": "mall", "walk": "w2.txt.gz", "digest": "d2|shared:L21",
    "summary": dict(FIGURES, quarantine=[], start_after=None), "device": "", "clock": None,
    "ended": None, "floor_name": None, "status": "ok", "seconds": 0.2,
    "start_inference": {"candidates": [["L27", 0.0]], "stand": None, "tau_dbm": -85.0},
    "start_shared": {"start": "L21", "with": ["mall/w3"], "totals": {"L21": 0.4, "L27": 1.5},
                     "kept": True},
}  # fmt: skip
FAILED = {
    "key": "mall/w4", "building": "mall", "walk": "w4.txt.gz", "digest": "d4",
    "status": "failed", "error": "Unreadable: gone", "trace": "Traceback …", "retry": True,
    "seconds": 0.01,
}  # fmt: skip


@pytest.mark.parametrize("stored", [HANDED, SHARED, FAILED], ids=["handed", "shared", "failed"])
def test_a_stored_result_reads_back_and_writes_unchanged(tmp_path, stored):
    res = WalkResult.from_json(json.loads(json.dumps(stored)))
    assert json.loads(summary_text(res)) == stored
    records = Records(tmp_path)
    records.write(res)
    again = Records(tmp_path).get(res.key)  # what the next pass reads from the file
    assert again == res and json.loads(summary_text(again)) == stored


def test_the_passes_read_fields_not_keys():
    res = WalkResult.from_json(HANDED)
    assert (
        res.ok and res.summary.start_node == "L27" and res.summary.reasons == ("start_ambiguous",)
    )
    assert res.start_inference is not None and res.start_inference.candidates[1] == ("L21", 1.04)
    assert res.start_inference.stand == (("aa:bb", "cc:dd"), (-61.5, -70.25))
    assert res.clock == (1574300000.5, 1574300060.0) and res.ended == (80.5, 95.25, 0.0, 1.3)
    assert (
        res.start_after
        == res.summary.start_after
        == HandedStart("w0", 4.1, (80.5, 95.25, 0.0), 9.5, 3, False)
    )
    assert res.start_after.region == (80.5, 95.25, 0.0, 9.5)
    shared = WalkResult.from_json(SHARED).start_shared
    assert shared is not None and shared.kept and shared.walks == ("mall/w3",)
    failed = WalkResult.from_json(FAILED)
    assert not failed.ok and failed.retry and failed.summary.start_node == ""


def test_a_walk_never_run_is_missing(tmp_path):
    res = Records(tmp_path).get("mall/never")
    assert res.key == "mall/never" and res.status == "missing" and not res.ok
    assert res.start_inference is None and res.figures == {}
