"""The Rerun recording of a museum walk (IPIN 2023, sparse ground truth: fixes at landmarks),
read back from the saved .rrd: what lies on top of what on the plan (issue #50 item 5)."""

import numpy as np
import pytest
from rerun.chunk import RrdReader

from tests.conftest import IPIN, need
from workstation.cli import main
from workstation.viz.layouts import floor_path

WALK = "IPIN2023_T3_TrainingTrial51_repetition02.txt"
FIX_R = 0.3  # the fixes' radius (m)
BOX_M = 1.0  # a label box's height and half width at the default view (m; ~20 × 40 px)


@pytest.fixture(scope="module")
def museum_rrd(tmp_path_factory):
    tra = sorted((need(IPIN) / "supplementary" / "trajectories").glob("*.tra"))
    d = tmp_path_factory.mktemp("museum_rrd")
    assert main(["graph", "from-tra", *map(str, tra), "-o", str(d / "g.yaml")]) == 0
    out = d / "walk.rrd"
    assert main(["view", str(IPIN / "logfiles" / WALK), "--graph", str(d / "g.yaml"),
                 "--start", "first-fix", "--save", str(out)]) == 0  # fmt: skip
    return out


def _entities(path) -> dict[str, dict[str, list]]:
    """entity → component (short name) → every value logged, static or not."""
    out: dict[str, dict[str, list]] = {}
    for ch in RrdReader(path).stream():
        b = ch.to_record_batch()
        comps = out.setdefault(ch.entity_path, {})
        for name in b.schema.names:
            comps.setdefault(name.rsplit(":", 1)[-1], []).extend(b.column(name).to_pylist())
    return out


def _flat(rows) -> list:
    """A scalar component's values over its rows (each row a list, or None where not logged)."""
    return [v for row in rows if row for v in row]


def _xy(values) -> np.ndarray:
    rows = [p for v in values if v for p in v]
    return np.array(rows, float).reshape(-1, 2)


def test_no_landmark_label_lies_over_a_ground_truth_fix(museum_rrd):
    """Rerun draws a point's label box from just below its centre down; the ids were logged on
    the landmarks themselves, so each box hid the fix at its landmark (L74, L75). A box (about
    1 m × 2 m at the default view) starting at any label anchor must not reach a fix."""
    ents = _entities(museum_rrd)
    floors = [p.split("/")[2] for p in ents if p.endswith("/ground_truth/fixes") and p.startswith("/map/")]
    assert len(floors) == 3  # the walk's floors −2, −1, 0
    for f in floors:
        fixes = _xy(ents[f"/map/{f}/ground_truth/fixes"]["positions"])
        anchors = _xy([v for path, c in ents.items() if path.startswith(f"/map/{f}/graph/")
                       and _flat(c.get("show_labels", [])) == [True] for v in c["positions"]])
        assert len(fixes) and len(anchors)
        dx = np.abs(anchors[None, :, 0] - fixes[:, None, 0])
        dy = fixes[:, None, 1] - anchors[None, :, 1]  # display y grows downwards
        covered = (dx < BOX_M) & (dy > -FIX_R) & (dy < BOX_M + FIX_R)
        assert not covered.any(), (f, fixes[covered.any(axis=1)])
        # the landmarks keep their ids for hovering, without drawing them
        assert ents[f"/map/{f}/graph/nodes"]["labels"]
        assert _flat(ents[f"/map/{f}/graph/nodes"]["show_labels"]) == [False]


def test_the_fixes_are_drawn_over_the_landmarks_points_and_tracks(museum_rrd):
    """The fix at L75 sat under a pile of reference points: every fix and the truth line are now
    drawn over each other point or line layer of the floor (Rerun's defaults: lines 20, points
    30), in the floor tabs and the Walker's floor alike (which had no fixes at all)."""
    ents = _entities(museum_rrd)
    for root in (f"/map/{floor_path(-1.0)}", "/walker_floor"):
        fixes = ents[f"{root}/ground_truth/fixes"]
        assert fixes["positions"] and any(v for v in fixes["positions"])
        top = min(_flat(fixes["draw_order"]))
        for path, comps in ents.items():
            drawn = {"positions", "strips"} & set(comps)
            if not path.startswith(root + "/") or not drawn or "ground_truth" in path:
                continue
            if path.endswith(("/walker", "/graph/labels", "_label")):
                continue  # the walker now, and the ids (drawn as text, not as points)
            default = 20.0 if "strips" in comps else 30.0
            order = _flat(comps.get("draw_order", [])) or [default]
            assert max(order) < top, (path, order)


def test_a_crowded_floor_keeps_its_landmark_ids_for_hovering():
    """The mall's 261 landmark labels hid its plan and the walk in Rerun: beyond LABELS_MAX a
    floor's ids are shown on hover only; the museum's and the office's floors keep theirs."""
    from workstation.graph import Landmark, LandmarkGraph
    from workstation.viz.rerun_graph import LABELS_MAX, graph_on_floor

    def drawn(n):
        g = LandmarkGraph(tuple(Landmark(f"L{i}", float(i), 0.0, 0.0) for i in range(n)), ())
        layers = graph_on_floor(g, 0.0)
        assert len(layers["graph/nodes"].labels.as_arrow_array()) == n  # on hover, always
        return layers["graph/labels"] is not None

    assert drawn(LABELS_MAX) and not drawn(LABELS_MAX + 1)
