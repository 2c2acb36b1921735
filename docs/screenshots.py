"""Make the README's pictures of the two real buildings (issue #30), from ../shared/data:
the museum's floor −1 (IPIN 2023, its plan placed by the .cal) and the mall's floor F1
(Microsoft ILC, 106 walks' graph), each

- in the survey panel (headless Chromium, the walk and its ground truth on the plan),
- in the Rerun viewer (headless): the Walker's floor tab and the floor's own tab,
- from `workstation quality` (coverage of the walk's radio map on the plan);

and a mall walk the pipeline quarantines (its start inferred, ambiguous) in the panel and
Rerun, the mall floor's survey plan (`workstation plan`), and the office walk with its plan's
route in Rerun (`view --route`) — docs/reference.md's pictures.

    .venv/bin/python docs/screenshots.py [--out docs/img]

Needs ../shared/data, Debian chromium (playwright) and mesa-vulkan-drivers (the viewer). Every
picture is opened and judged before it goes into the README: this only makes them.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data"
IPIN = DATA / "ipin2023-track3"
MALL = DATA / "microsoft-ilc2020-site1-f1"
WS = [sys.executable, "-m", "workstation"]


def _ws(*args, ok: tuple[int, ...] = (0,)) -> None:
    """A workstation command; exit codes ``ok`` (3: the walk is quarantined) go on."""
    done = subprocess.run([*WS, *map(str, args)], cwd=REPO, stdout=subprocess.DEVNULL)
    if done.returncode not in ok:
        raise subprocess.CalledProcessError(done.returncode, done.args)


def museum(tmp: Path) -> dict:
    graph, building = tmp / "museum.yaml", tmp / "museum_building.yaml"
    _ws("graph", "from-tra", *sorted((IPIN / "supplementary" / "trajectories").glob("*.tra")),
        "-o", graph)  # fmt: skip
    _ws("building", "from-ipin-cal", IPIN / "supplementary" / "calib_mapa_Nuremberg.cal",
        "--graph", graph, "-o", building)  # fmt: skip
    walk = IPIN / "logfiles" / "IPIN2023_T3_TrainingTrial51_repetition02.txt"
    return {"name": "museum", "graph": graph, "building": building, "walk": walk, "floor": -1.0}


def mall(tmp: Path) -> dict:
    graph, building = tmp / "mall.yaml", tmp / "mall_building.yaml"
    walks = sorted((MALL / "path_data_files").glob("*"))
    _ws("graph", "from-waypoints", *walks, "-o", graph)
    _ws("building", "from-msilc", MALL / "floor_info.json", "--floor", "0", "-o", building)
    walk = max(walks, key=lambda p: p.stat().st_size)  # the longest walk of the floor
    return {"name": "mall", "graph": graph, "building": building, "walk": walk, "floor": 0.0}


def quarantined(mall_b: dict) -> dict:
    """A mall F1 walk whose inferred start is ambiguous (L133, L199 nearly as likely): the
    pipeline quarantines it and places it 57 m off."""
    walk = MALL / "path_data_files" / "5dd9ef979191710006b57086.txt.gz"
    return mall_b | {"name": "quarantined_mall", "walk": walk, "start": "infer"}


def plan_png(b: dict, png: Path, tmp: Path) -> None:
    """`workstation plan` on the mall floor's graph (walks of at most 10 minutes): its PNG."""
    _ws("plan", "--graph", b["graph"], "--building", b["building"], "--max-minutes", "10",
        "--out", tmp / "plan")  # fmt: skip
    shutil.copy(tmp / "plan" / f"plan_floor_{b['floor']:g}.png", png)


def office_route(png: Path, tmp: Path) -> None:
    """The bundled office walk in Rerun with its survey plan's route (`view --route`)."""
    office = REPO / "sample_sessions" / "office2f" / "normal"
    _ws("plan", "--graph", office / "graph.yaml", "--max-minutes", "5", "--out", tmp / "oplan")
    b = {"name": "office", "walk": office, "graph": office / "graph.yaml", "floor": 0.0,
         "start": "infer", "route": tmp / "oplan" / "plan.json"}  # fmt: skip
    rerun_shots(b, [None, png], tmp)


def _panel(b: dict, work: Path):
    """The panel on the walk from its first fix (or as ``b["start"]`` says), over the
    building's plan, as `edit` opens it."""
    from workstation.building import Building
    from workstation.editor import SurveyEditor
    from workstation.graph import LandmarkGraph
    from workstation.params import Params
    from workstation.pipeline.start import resolve_start
    from workstation.session import load_session
    from workstation.viz.panel import SurveyPanel

    work.mkdir(exist_ok=True)
    shutil.copy(b["graph"], work / "graph.yaml")
    session, graph = load_session(b["walk"]), LandmarkGraph.load(work / "graph.yaml")
    start = b.get("start", "first-fix")
    params = Params().updated(**{"pdr.start_node": resolve_start(start, session, graph)})
    ed = SurveyEditor(session, graph, params, graph_path=work / "graph.yaml", out_dir=work / "o")
    return SurveyPanel(ed, None, port=0, building=Building.load(b["building"]),
                       building_path=b["building"])  # fmt: skip


def _in_browser(b: dict, png: Path, work: Path, then) -> None:
    """The panel in headless chromium on floor ``b["floor"]`` (framed as the panel frames the
    walk there), ``then(panel, page, client)``, and the picture (without the notice chromium
    shows for software WebGL: no GPU here)."""
    from playwright.sync_api import sync_playwright

    from tests.viz.conftest import ARGS, framed, open_page

    panel = _panel(b, work)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True,
                                        args=ARGS)  # fmt: skip
            page = open_page(browser, panel)
            client = next(iter(panel.server.get_clients().values()))
            framed(panel, client)
            if panel.floor != b["floor"]:  # the walk's floor when it opens
                panel.show_floor(b["floor"])
                panel.redraw()
                panel._frame_camera()
                panel.draw.reset_view(client)
            then(panel, page, client)
            notice = page.locator("[class*=Notification-root] button")
            for k in range(notice.count()):
                notice.nth(k).click()
            time.sleep(2)
            page.screenshot(path=str(png))
            browser.close()
    finally:
        panel.stop()


def panel_shot(b: dict, png: Path) -> None:
    """The panel at its default view, as a surveyor gets it (issue #50 item 5)."""
    _in_browser(b, png, png.parent / f".{b['name']}_panel", lambda *_: time.sleep(4))


def plan_shot(b: dict, png: Path) -> None:
    """The panel with "Plan the walk" pressed (walks of at most 10 minutes over the graph)."""
    from tests.viz.conftest import wait_for

    def plan(panel, page, client) -> None:
        if b["name"] == "mall":  # the plan covers the floor (the museum's: the walk's part)
            page.get_by_role("button", name="Whole floor").click()
        page.get_by_text("Survey plan", exact=True).click()
        page.get_by_role("button", name="Plan the walk").click()
        wait_for(lambda: panel.route.plan is not None, timeout=300)
        time.sleep(4)
        page.get_by_role("button", name="Plan the walk").scroll_into_view_if_needed()

    _in_browser(b, png, png.parent / f".{b['name']}_plan", plan)


def rerun_shots(b: dict, pngs: list[Path | None], tmp: Path) -> None:
    """The recording as `workstation view --save`, opened in a headless viewer at a moment the
    walker is on the floor: its own blueprint (the Walker's floor tab open), then with the
    floor's tab active (a picture None: not taken)."""
    import numpy as np
    import pandas as pd
    import rerun as rr

    from workstation.viz.rerun_log import spawn_viewer, stop_viewer

    rrd = tmp / f"{b['name']}.rrd"
    extra = [*(["--building", b["building"]] if b.get("building") else []),
             *(["--route", b["route"]] if b.get("route") else [])]  # fmt: skip
    _ws("view", b["walk"], "--graph", b["graph"], *extra, "--start", b.get("start", "first-fix"),
        "--save", rrd, ok=(0, 3))  # fmt: skip
    tr = pd.read_csv(_run(b, tmp) / "trajectory.csv")
    on = tr[(tr["floor"] == b["floor"]) & (tr["segment"] >= 0)]
    at = float(np.percentile(on["t"], 80))  # late on the floor: most of its walk drawn
    os.environ.setdefault("WGPU_BACKEND", "vulkan")
    for k, png in enumerate(pngs):
        if png is None:
            continue
        proc, url = spawn_viewer(headless=True)
        viewer = rr.experimental.ViewerClient(url)
        try:
            viewer.open(str(rrd))
            deadline = time.time() + 60
            while time.time() < deadline and not viewer.get_state().views:
                time.sleep(0.5)
            state = viewer.get_state()
            if k == 0 and "Walker's floor" not in {v.name for v in state.views}:
                continue  # one floor: its tab is all there is
            if k:  # the floor's own tab: the same blueprint with that tab active
                view = next(v for v in state.views if v.name == f"Floor {b['floor']:g}")
                bp = viewer.get_blueprint().blueprint
                for entry in bp.values():
                    c = entry.get("ContainerBlueprint", {})
                    for item in c.get("contents", []):
                        if str(item).endswith(view.view_id):
                            c["active_tab"] = item
                viewer.set_blueprint(bp, of="recording")
                time.sleep(2)
            viewer.set_time(timeline="time", duration=at, play_state="paused")
            time.sleep(8)
            viewer.save_screenshot(str(png))
        finally:
            stop_viewer(proc)


def _run(b: dict, tmp: Path) -> Path:
    run = tmp / f"{b['name']}_run"
    if not (run / "trajectory.csv").is_file():
        subprocess.run(
            [
                *WS,
                "run",
                str(b["walk"]),
                "--graph",
                str(b["graph"]),
                "--start",
                b.get("start", "first-fix"),
                "--out",
                str(run),
            ],
            cwd=REPO,
            stdout=subprocess.DEVNULL,
        )  # fmt: skip  (exit 3 when quarantined)
    return run


def quality_shot(b: dict, png: Path, tmp: Path) -> None:
    run, q = _run(b, tmp), tmp / f"{b['name']}_quality"
    _ws("quality", "--map", run / "radiomap.csv", "--graph", b["graph"], "--building",
        b["building"], "--include-quarantined", "--out", q)  # fmt: skip
    shutil.copy(q / f"floor_{b['floor']:g}_coverage.png", png)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "img")
    ap.add_argument("--only", nargs="*",
                    default=["panel", "rerun", "quality", "plan", "quarantined", "route"])
    args = ap.parse_args()
    if not (IPIN.is_dir() and MALL.is_dir()):
        print(f"needs {IPIN} and {MALL}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for b in (museum(tmp), mall(tmp)):
            f = f"floor{b['floor']:g}"
            if "panel" in args.only:
                panel_shot(b, args.out / f"panel_{b['name']}_{f}.png")
            if "rerun" in args.only:
                rerun_shots(b, [args.out / f"rerun_{b['name']}_walkers_floor.png",
                                args.out / f"rerun_{b['name']}_{f}.png"], tmp)  # fmt: skip
            if "plan" in args.only:
                name = "mall" if b["name"] == "mall" else f"{b['name']}_{f}"
                plan_shot(b, args.out / f"panel_survey_plan_{name}.png")
            if "quality" in args.only:
                quality_shot(b, args.out / f"quality_{b['name']}_{f}.png", tmp)
        if "quarantined" in args.only:
            q = quarantined(b)  # (b: the mall, the loop's last)
            panel_shot(q, args.out / "panel_quarantined_mall.png")
            rerun_shots(q, [None, args.out / "rerun_quarantined_mall.png"], tmp)
        if "route" in args.only:
            plan_png(b, args.out / "plan_floor_mall.png", tmp)
            office_route(args.out / "rerun_office_plan_route.png", tmp)
        for p in [*args.out.glob(".*_panel"), *args.out.glob(".*_plan")]:
            shutil.rmtree(p, ignore_errors=True)
    print(f"wrote the pictures to {args.out}: open and judge each before using it")
    return 0


if __name__ == "__main__":
    sys.exit(main())
