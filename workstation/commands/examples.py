"""An example (and, where the command has none, a description) for every command's help: each
runs as written from the checkout, on the bundled samples (the museum ones need ../shared)."""

from __future__ import annotations

import argparse

S = "sample_sessions/office2f/normal"
MS = "sample_sessions/msilc-site1-f1-walk"
TRA = "../shared/data/ipin2023-track3/supplementary"

EXAMPLES: dict[str, tuple[str, str]] = {
    # command path: (description used when the parser has none, example)
    "layouts": (
        "Write overview.rbl, landmarks.rbl and radiomap.rbl for the given floors.",
        "workstation layouts --out layouts",
    ),
    "localize": (
        "Localize every scan of a walk on a radio map by 1-NN (or kNN) and print the "
        "errors against its ground truth; --uji runs the UJIIndoorLoc benchmark.",
        "workstation localize --map out/normal/radiomap.csv --session "
        "sample_sessions/office2f/heldout",
    ),
    "merge": (
        "Merge radio maps (CSV, Parquet) of one building into one, each walk's device "
        "offset removed.",
        "workstation merge out/a/radiomap.csv out/b/radiomap.csv -o out/merged.csv",
    ),
    "evaluate": (
        "",
        "workstation evaluate --out docs    |    workstation evaluate --walks "
        "walks/*.txt --graph museum.yaml --out out/museum",
    ),
    "simulate": (
        "Simulate a walk (normal, varied, heldout) or a manual survey (survey5, "
        "survey10) in a simulated building (office2f, office3f) as a session folder "
        "with graph.yaml and floorplan.yaml.",
        "workstation simulate --building office3f --walk normal --seed 2 --out out/sim",
    ),
    "graph": (
        "Build landmark graphs from IPIN route files or from walks' tapped waypoints, and "
        "check them.",
        f"workstation graph from-tra {TRA}/trajectories/*.tra -o museum.yaml",
    ),
    "graph from-tra": ("", f"workstation graph from-tra {TRA}/trajectories/*.tra -o museum.yaml"),
    "graph from-waypoints": ("", f"workstation graph from-waypoints {MS} -o out/graph.yaml"),
    "graph validate": ("", f"workstation graph validate {S}/graph.yaml"),
    "building": (
        "",
        f"workstation building from-msilc {MS}/floor_info.json --floor 0 -o out/building.yaml",
    ),
    "building from-ipin-cal": (
        "",
        f"workstation building from-ipin-cal "
        f"{TRA}/calib_mapa_Nuremberg.cal --graph museum.yaml "
        f"-o museum.building.yaml",
    ),
    "building from-msilc": (
        "",
        f"workstation building from-msilc {MS}/floor_info.json --floor 0 -o out/building.yaml",
    ),
    "building from-points": (
        "",
        f"workstation building from-points {MS}/floor_image.png "
        f"--point 0,0=0,0 --point 100,0=10,0 -o out/building.yaml",
    ),
    "building validate": ("", f"workstation building validate {MS}/building.yaml"),
    "campaign": ("", "workstation campaign run my_campaign --out out/campaign --workers 2"),
    "campaign run": (
        "Run every walk whose inputs changed since the last run (or all with "
        "--force), merge each building's radio map, write campaign.json/.md.",
        "workstation campaign run my_campaign --out out/campaign --workers 2",
    ),
    "quality": (
        "",
        f"workstation quality --map out/normal/radiomap.csv --graph {S}/graph.yaml "
        f"--out out/quality",
    ),
    "plan": (
        "Plan the survey walk that covers every edge of the graph (or, with --map or "
        "--quality, the re-walk of the edges the map covers thinly), cut into walks, with "
        "what to do at each landmark: plan.md, plan.json, plan.geojson.",
        f"workstation plan --graph {S}/graph.yaml --max-minutes 5 --out out/plan",
    ),
    "demo": (
        "Run the pipeline on the bundled simulated office walk, write its results and "
        "its Rerun recording, and open the viewer when a display exists.",
        "workstation demo --out out",
    ),
}


# the help of arguments many commands share, where a command gives none
ARGUMENTS = {
    "session": "the walk: a GetSensorData/IPIN logfile, a Microsoft ILC path file or a session "
    "folder",
    "sessions": "walks with ground-truth (tapped) waypoints",
    "graph": "the landmark graph YAML of the walk's building",
    "params": "parameter YAML (default: the defaults, docs/decisions.md)",
    "out": "output folder (created)",
    "output": "output file (written atomically, the previous one kept as .bak)",
    "port": "port of the panel (default 8080; 0 picks a free one)",
    "maps": "radio maps (CSV, Parquet)",
    "files": "IPIN .tra route files",
    "cal": "the IPIN .cal calibration file (its images beside it)",
    "info": "the Microsoft ILC floor_info.json",
    "image": "the plan image (PNG, JPEG)",
    "building": "the building file (YAML)",
    "campaign": "a campaign folder (buildings/<name>/...) or a YAML listing",
    "path": "a walk (logfile, path file or session folder)",
    "map": "a radio map (CSV, Parquet)",
    "seed": "random seed (same seed, same walk)",
    "floor": "the floor number",
    "metric": "distance between fingerprints (default euclidean; the paper uses both)",
    "k": "neighbours averaged (1: the paper's 1-NN)",
    "walks": "walks (logfiles, path files or session folders)",
}


def apply(parser) -> None:
    """Set the examples (and missing descriptions) on ``parser``'s subcommands; a command
    still without a description gets its one-line help, an argument without help the shared
    one."""
    for path, (description, example) in EXAMPLES.items():
        p = parser
        for word in path.split():
            p = _sub(p)[word]
        if not p.description and description:
            p.description = description
        if not p.epilog:
            p.epilog = f"example: {example}"
    _describe(parser)


def _describe(parser) -> None:
    for a in parser._actions:
        if a.help is None and a.dest in ARGUMENTS:
            a.help = ARGUMENTS[a.dest]
        if isinstance(a, argparse._SubParsersAction):
            helps = {c.dest: c.help for c in a._choices_actions}
            for name, sp in a.choices.items():
                said = helps.get(name)
                if not sp.description and said:
                    sp.description = said[0].upper() + said[1:] + "."
                _describe(sp)


def _sub(parser):
    for a in parser._actions:  # argparse keeps subcommands there
        if isinstance(a, argparse._SubParsersAction):
            return a.choices
    raise KeyError(parser.prog)
