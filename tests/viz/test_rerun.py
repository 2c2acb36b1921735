"""The Rerun recording: read back the saved .rrd and check entities and values."""

import os
import shutil

import numpy as np
import pytest
from rerun.chunk import RrdReader

from tests.conftest import REPO
from workstation.cli import main
from workstation.graph import LandmarkGraph
from workstation.pipeline import Pipeline
from workstation.session import load_session
from workstation.viz.layouts import LAYOUTS, floor_path, write_layouts

WALK = REPO / "sample_sessions" / "office2f" / "normal"


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    out = tmp_path_factory.mktemp("rrd") / "normal.rrd"
    assert main(["view", str(WALK), "--graph", str(WALK / "graph.yaml"), "--save", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def expected():
    s = load_session(WALK)
    g = LandmarkGraph.load(WALK / "graph.yaml")
    pipe = Pipeline(s, g)
    r = pipe.run()
    return s, r, r.summary(pipe.session, g).to_json()


def _have_viewer() -> bool:
    """The venv's `rerun` (beside this Python; make test does not put the venv on PATH) and a
    Vulkan driver (Debian mesa-vulkan-drivers)."""
    import sys
    from pathlib import Path

    exe = Path(sys.executable).with_name("rerun")
    return (exe.exists() or shutil.which("rerun") is not None) and os.path.exists(
        "/usr/share/vulkan/icd.d"
    )


def rows(path, entity):
    """Rows on the timeline (static styling rows not counted)."""
    n = 0
    for ch in RrdReader(path).stream():
        if ch.entity_path == entity and not ch.is_static:
            n += ch.to_record_batch().num_rows
    return n


def column(path, entity, component):
    vals = []
    for ch in RrdReader(path).stream():
        if ch.entity_path == entity:
            b = ch.to_record_batch()
            name = next((c for c in b.schema.names if c.endswith(component)), None)
            if name is None:
                continue
            vals += b.column(name).to_pylist()
    return vals


def test_entities_mirror_the_pipeline(recording):
    paths = {ch.entity_path for ch in RrdReader(recording).stream()}
    for p in [
        "/sensors/accelerometer/x", "/sensors/gyroscope/z", "/sensors/magnetometer/y", "/sensors/pressure",
        "/sensors/wifi/aps_per_scan", "/steps/period", "/steps/walking", "/heading/vertical_rate/rate",
        "/landmarks/log", "/landmarks/confidence/gyro", "/belief/segment", "/belief/threshold",
        "/map/floor_0/graph/nodes", "/map/floor_0/graph/edges", "/map/floor_0/plan/walls",
        "/map/floor_0/raw_pdr", "/map/floor_0/trajectory", "/map/floor_0/ground_truth",
        "/map/floor_0/walker", "/map/floor_1/reference_points/accepted", "/summary",
    ]:  # fmt: skip
        assert p in paths, p


def test_values_match_the_pipeline(recording, expected):
    s, r, summ = expected
    assert rows(recording, "/sensors/accelerometer/x") == len(s.accelerometer)
    assert rows(recording, "/sensors/pressure") == len(s.pressure)
    # step periods, stands (gaps over 2 T_max) left out
    p = r.steps.period
    assert rows(recording, "/steps/period") == np.count_nonzero(np.isfinite(p) & (p <= 2.0))
    texts = [t for row in column(recording, "/landmarks/log", "text") for t in row]
    # every detection, and where the walk ends when its end closed on a landmark
    assert len(texts) == summ["landmarks_detected"] + bool(summ["end_node"])
    assert sum("the walk ends on" in t for t in texts) == bool(summ["end_node"])
    # the time is in the text (the viewer's time column is too narrow for it)
    times = [float(t.split()[1]) for t in texts]
    assert times == sorted(times) and times[-1] > 60.0 and all(t.startswith("t ") for t in texts)
    assert sum("→ matched" in t for t in texts) == summ["landmarks_matched"]
    spread = r.track.detections.spread[
        r.track.detections.matched
    ]  # said where another landmark was as likely
    assert sum("nearly as likely" in t for t in texts) == np.count_nonzero(spread > 0)
    assert (
        sum("rejected" in t for t in texts)
        == summ["landmarks_detected"] - summ["landmarks_matched"]
    )
    accepted = sum(
        len(v)
        for f in ("floor_0", "floor_1")
        for v in column(recording, f"/map/{f}/reference_points/accepted", "positions")
    )
    assert accepted == summ["reference_points"]
    nodes = sum(
        len(v)
        for f in ("floor_0", "floor_1")
        for v in column(recording, f"/map/{f}/graph/nodes", "positions")
    )
    assert nodes == 20
    acc_x = np.concatenate(
        [np.asarray(column(recording, "/sensors/accelerometer/x", "scalars"), float).ravel()]
    )
    assert np.allclose(acc_x, s.accelerometer.xyz[:, 0])


def test_recording_carries_the_blueprint(recording):
    assert len(RrdReader(recording).blueprints()) == 1


def test_layouts_are_generated_from_code(tmp_path):
    files = write_layouts(tmp_path)
    assert sorted(p.stem for p in files) == sorted(LAYOUTS)
    for p in files:
        bp = RrdReader(p).blueprints()
        assert bp and bp[0].application_id == "workstation"
        assert (REPO / "layouts" / p.name).is_file(), (
            f"layouts/{p.name} missing: run `make layouts`"
        )


def test_unknown_layout_is_refused(tmp_path, capsys):
    assert (
        main(
            [
                "view",
                str(WALK),
                "--graph",
                str(WALK / "graph.yaml"),
                "--layout",
                "nope",
                "--save",
                str(tmp_path / "x.rrd"),
            ]
        )
        == 2
    )
    assert "unknown layout 'nope'" in capsys.readouterr().err


@pytest.mark.viewer
def test_headless_viewer_opens_the_recording(recording, tmp_path):
    import rerun as rr

    if not _have_viewer():
        pytest.skip("headless Rerun viewer needs mesa-vulkan-drivers")
    from workstation.viz.rerun_log import spawn_viewer, stop_viewer

    os.environ.setdefault("WGPU_BACKEND", "vulkan")
    proc, url = spawn_viewer(headless=True)  # bound to 127.0.0.1
    viewer = rr.experimental.ViewerClient(url)
    try:
        viewer.open(str(recording))
        import time

        deadline = time.time() + 30
        views = []
        while time.time() < deadline:
            views = viewer.get_state().views
            if views:
                break
            time.sleep(0.5)
        assert len(views) >= 4
        logs = viewer.get_logs()
        # the machine's software rasterizer warns about itself; anything else is ours
        bad = [
            e
            for e in logs
            if e.level.upper() in ("ERROR", "WARN", "WARNING")
            and "Software rasterizer" not in e.message
        ]
        assert not bad, bad
        viewer.save_screenshot(str(tmp_path / "viewer.png"))
        assert (tmp_path / "viewer.png").stat().st_size > 10_000
    finally:
        stop_viewer(proc)


@pytest.mark.viewer
def test_view_streams_to_a_running_viewer(tmp_path):
    import time

    import rerun as rr

    if not _have_viewer():
        pytest.skip("headless Rerun viewer needs mesa-vulkan-drivers")
    from workstation.viz.rerun_log import spawn_viewer, stop_viewer

    os.environ.setdefault("WGPU_BACKEND", "vulkan")
    proc, url = spawn_viewer(headless=True)
    try:
        assert main(["view", str(WALK), "--graph", str(WALK / "graph.yaml"), "--connect", url]) == 0
        viewer = rr.experimental.ViewerClient(url)
        deadline = time.time() + 30
        views = []
        while time.time() < deadline and len(views) < 4:
            views = viewer.get_state().views
            time.sleep(0.5)
        assert len(views) >= 4
    finally:
        stop_viewer(proc)


def test_colours_read_on_the_dark_theme_and_a_legend_is_logged(recording):
    """Issue #14: nothing important is drawn near-black on the viewer's dark background, raw PDR
    is not the walls' grey, and the recording carries a legend."""
    from workstation.viz.colours import MAP, SERIES

    for name, (col, _) in {**MAP, **SERIES}.items():
        assert max(col[:3]) >= 100, name
    assert MAP["raw_pdr"][0] != MAP["walls"][0]
    paths = {ch.entity_path for ch in RrdReader(recording).stream()}
    assert "/legend" in paths
    text = column(recording, "/legend", "TextDocument:text")
    assert text and "ground truth" in str(text[0])


def test_radiomap_quality_is_logged_per_floor(recording):
    """Issue #15: the coverage map and the strongest APs' heatmaps under /map/<floor>/quality."""
    paths = {ch.entity_path for ch in RrdReader(recording).stream()}
    assert "/map/floor_0/quality/coverage" in paths and "/map/floor_1/quality/coverage" in paths
    assert sum(p.startswith("/map/floor_0/quality/ap/") for p in paths) == 5


def test_a_map_follows_the_walkers_floor(recording, expected):
    """Issue #14: /walker_floor holds the graph of the floor the walker entered, logged at each
    floor change, and the walker at every step; the overview opens on it."""
    from workstation.viz.follow import floor_changes

    _, r, _ = expected
    changes = floor_changes(r.track.steps.floor)
    assert len(changes) >= 3  # the office walk goes 0 → 1 → 0
    assert rows(recording, "/walker_floor/graph/nodes") == len(changes)
    labels = column(recording, "/walker_floor/graph/nodes", "labels")
    on = [{lab[-1] for lab in row} for row in labels if row]  # the floor digit of each node id
    assert on == [{str(int(r.track.steps.floor[i]))} for i in changes]
    assert rows(recording, "/walker_floor/walker") == r.track.steps.t.size


def _origins(item) -> list[str]:
    """Every view's origin in a blueprint's container tree."""
    if hasattr(item, "origin"):  # a view (containers hold views and containers)
        return [str(item.origin)]
    return [o for k in item.contents for o in _origins(k)]


def test_a_walk_without_a_barometer_gets_no_empty_pressure_plot_and_stands_no_step_period(
    recording, expected
):
    """Issue #30 item 4: walks with no barometer showed an empty pressure plot; one 30-s stand
    stretched the step-period axis until the steps were a flat line."""
    from workstation.viz.layouts import blueprint

    for layout in ("overview", "landmarks"):
        assert "/sensors/pressure" in _origins(blueprint(layout, [0.0]).root_container)
        assert "/sensors/pressure" not in _origins(
            blueprint(layout, [0.0], pressure=False).root_container
        )
    _, r, _ = expected
    stands = r.steps.period[np.isfinite(r.steps.period)] > 2.0
    assert stands.any()  # the office walk stands: the test means something
    periods = np.concatenate([np.ravel(v) for v in column(recording, "/steps/period", "scalars")])
    assert periods.size > 100 and periods.max() <= 2.0


def test_the_walker_is_drawn_only_on_the_floor_it_is_on(recording, expected):
    """Issue #30 item 4: each floor's walker dot stayed where the walker left that floor (at
    200 s it showed on all three). Every step logs the dot on its floor and none elsewhere."""
    _, r, _ = expected
    tr = r.track
    assert np.unique(tr.steps.floor).size > 1  # the office walk changes floor
    for f in np.unique(tr.steps.floor):
        rows_ = column(recording, f"/map/floor_{f:g}/walker", "positions")
        assert len(rows_) == tr.steps.t.size  # one row per step
        shown = np.array([len(v or []) for v in rows_])
        assert np.array_equal(shown, (tr.steps.floor == f).astype(int)), f


def test_the_walkers_floor_tab_shows_what_the_floor_tabs_show(recording, expected):
    """Issue #30 item 4: the tab that opens first had only the graph and our trajectory. It now
    draws plain PDR, the ground truth and the reference points of the walker's floor, changed
    with the floor: the accepted points drawn at each change are those of the floor entered."""
    _, r, _ = expected
    paths = {ch.entity_path for ch in RrdReader(recording).stream()}
    for p in ("/walker_floor/raw_pdr", "/walker_floor/ground_truth",
              "/walker_floor/reference_points/accepted"):  # fmt: skip
        assert p in paths, p
    shown = column(recording, "/walker_floor/reference_points/accepted", "positions")
    tr, rm = r.track, r.radiomap
    changes = np.flatnonzero(np.r_[True, tr.steps.floor[1:] != tr.steps.floor[:-1]])
    assert len(shown) == changes.size > 1
    want = sorted(int((rm.accepted & (rm.floor == tr.steps.floor[i])).sum()) for i in changes)
    assert sorted(len(v or []) for v in shown) == want


def test_the_walkers_floor_tab_shows_the_plan_of_the_floor_the_walker_is_on(tmp_path, expected):
    """Issue #30 item 4: the Walker's floor tab had no plan image. Each floor's image is static
    under /walker_floor/plan/<floor>/image with its own transform (a timed image Rerun 0.41 drew
    in pixels); its parent's transform puts it in place while the walker is on that floor and
    far away while not — checked at every floor change of the office walk (0 → 1 → 0)."""
    from PIL import Image

    from workstation.building import Building, FloorImage, FloorInfo
    from workstation.viz.follow import FAR_M, floor_changes

    _, r, _ = expected
    floors = {}
    for f in (0.0, 1.0):
        png = tmp_path / f"plan{f:g}.png"
        Image.new("RGB", (40, 30), (200, 200, 200)).save(png)
        floors[f] = FloorInfo(None, FloorImage(png, np.array([[1.0, 0, 0], [0, -1.0, 30.0]])))
    Building("office", floors).save(tmp_path / "building.yaml")
    out = tmp_path / "plans.rrd"
    assert main(["view", str(WALK), "--graph", str(WALK / "graph.yaml"), "--building",
                 str(tmp_path / "building.yaml"), "--save", str(out)]) == 0  # fmt: skip
    tr = r.track
    on = [tr.steps.floor[i] for i in floor_changes(tr.steps.floor)]
    assert len(on) >= 3
    for f in (0.0, 1.0):
        base = f"/walker_floor/plan/floor_{f:g}"
        assert rows(out, f"{base}/image") == 0  # static: drawn through its own transform
        assert column(out, f"{base}/image", "blob"), "no plan image"
        moved = [row[0] for row in column(out, base, "translation") if row]
        want = [[0.0, 0.0, 0.0] if g == f else [FAR_M, FAR_M, 0.0] for g in on]
        assert moved[-len(want) :] == want, (f, moved, on)


def test_a_quarantined_walk_looks_quarantined(tmp_path, capsys):
    """`view` says what `run` says of a walk it quarantines (the reason and what to do first,
    exit 3), and the recording shows it: the summary opens with the quarantine, its reasons
    and what to do (no raw key list, no 'None'), the corrected track in the quarantine colour
    (issue #50 item 2). A walk in the map says so too, and keeps its colours."""
    from workstation.pipeline.verdict import EXIT_QUARANTINED
    from workstation.viz.colours import rgb

    walk = REPO / "tests" / "data" / "msilc" / "5dd9e7c29191710006b57061.txt.gz"
    graph = REPO / "tests" / "data" / "msilc" / "site1_f1_graph.yaml"
    out = tmp_path / "q.rrd"
    code = main(["view", str(walk), "--graph", str(graph), "--start", "infer", "--save", str(out)])
    said = capsys.readouterr().out
    assert code == EXIT_QUARANTINED
    assert said.index("warning: quarantined") < said.index("saved")
    assert "what to do" in said.lower() or "Start here" in said
    assert said.rstrip().splitlines()[-1].startswith("quarantined:")
    (doc,) = [t for ts in column(out, "/summary", "text") for t in ts]
    assert doc.startswith("# QUARANTINED") and "start_ambiguous" in doc and "What to do" in doc
    assert "None" not in doc
    colours = column(out, "/map/floor_0/trajectory_corrected", "colors")
    want = int.from_bytes(bytes([*rgb("quarantined"), 255]), "big")
    assert want in [c for cs in colours if cs for c in (cs if isinstance(cs, list) else [cs])]
    assert main(["view", str(walk), "--graph", str(graph), "--start", "first-fix", "--save",
                 str(tmp_path / "ok.rrd")]) == 0  # fmt: skip
    (doc,) = [t for ts in column(tmp_path / "ok.rrd", "/summary", "text") for t in ts]
    assert doc.startswith("# Run summary: in the map")


def test_the_walks_start_end_and_direction_are_on_the_map(recording, expected):
    """Issue #50 item 3: the start, the end and the direction walked were nowhere on the map.
    Each is logged on its floor, labelled with the landmark and the time, and in the Walker's
    floor view."""
    s, r, summ = expected
    tr = r.track
    first = tr.steps.segment >= 0
    f0, f1 = (
        floor_path(float(tr.steps.floor[first][0])),
        floor_path(float(tr.steps.floor[first][-1])),
    )
    (start,) = column(recording, f"/map/{f0}/walk_marks/start_label", "Points2D:labels")
    assert start == [f"start {summ['start_node']} · {tr.steps.t[first][0]:.1f} s"]
    # the words below the mark, past the walker's sphere that sat on them (issue #64 item 5),
    # in a light shade that reads on the viewer's dark label box
    (at,) = column(recording, f"/map/{f0}/walk_marks/start_label", "Points2D:positions")
    (mark,) = column(recording, f"/map/{f0}/walk_marks/start", "Points2D:positions")
    assert at[0][1] - mark[0][1] > 1.2 and at[0][0] == mark[0][0]  # display y grows downwards
    (end,) = column(recording, f"/map/{f1}/walk_marks/end_label", "Points2D:labels")
    assert end[0].startswith(f"end {summ['end_node'] or '(open)'} · ")
    paths = {ch.entity_path for ch in RrdReader(recording).stream()}
    assert f"/map/{f0}/walk_marks/direction" in paths
    assert "/walker_floor/walk_marks/start" in paths
