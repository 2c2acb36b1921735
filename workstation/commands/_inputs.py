"""What the commands on a walk share (``info``, ``run``, ``view``, ``edit``, ``demo``): the walk
with its graph, parameters, building and plan, read and checked against each other, and the
host a server may bind to."""

from __future__ import annotations

import socket
from pathlib import Path

from workstation.building import Building
from workstation.building.consistency import check
from workstation.building.floorplan import FloorPlan
from workstation.commands.radiomap import read_maps
from workstation.errors import WorkstationError
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.io.store import is_remote, local_building, place, read_via_local, store_errors
from workstation.params import Params
from workstation.pipeline.start import resolve_end, resolve_start


def load_inputs(args, new_graph_ok: bool = False):
    from workstation.session import load_session

    # each may be a store's URL (a campaign there: the commands campaign.md gives, issue #54)
    session = read_via_local(args.session, load_session)
    with store_errors(args.graph):
        new = new_graph_ok and not place(args.graph).exists()
    if new:
        # a new graph, drawn in the panel, in the session's frame when it has one
        graph = LandmarkGraph((), (), session.frame, source=str(args.graph))
    else:
        graph = read_via_local(args.graph, LandmarkGraph.load)
    params = read_via_local(args.params, Params.load) if args.params else Params()
    if graph.nodes:
        check(session, graph, building_for(args), getattr(args, "force", False))
    if getattr(args, "start", None):
        params = params.updated(**{"pdr.start_node": resolve_start(args.start, session, graph)})
    if getattr(args, "end", None):
        params = params.updated(**{"pdr.end_node": resolve_end(args.end, session, graph)})
    return session, graph, params


def start_within(args, graph) -> tuple | None:
    """``--start-within X,Y,FLOOR,R``: where an inferred start is searched (None: anywhere;
    said when the reach holds no landmark)."""
    region = getattr(args, "start_within", None)
    if region and not graph.within(*region):
        print("note: no landmark within --start-within: the start is searched everywhere")
    return region


def building_path_for(args) -> Path | None:
    """The building file: ``--building``, else building.yaml beside the graph, else None; one
    in a store is copied here with its plan images (:func:`..io.store.local_building`)."""
    path = getattr(args, "building", None)
    if path is None and getattr(args, "graph", None):
        beside = place(args.graph).with_name("building.yaml")
        with store_errors(beside):
            path = beside if beside.is_file() else None
    if path is not None and is_remote(path):
        return local_building(path)
    return Path(path) if path else None


def building_for(args):
    """The building (:func:`building_path_for`), loaded, or None."""
    path = building_path_for(args)
    return Building.load(path) if path else None


def plan_for(args):
    if getattr(args, "plan", None):
        if Path(args.plan).suffix.lower() in (
            ".png",
            ".jpg",
            ".jpeg",
            ".gif",
            ".bmp",
            ".tif",
            ".tiff",
        ):
            raise WorkstationError(
                f"{args.plan}: --plan takes a wall plan (YAML); for a floor-plan image make a "
                "building file (workstation building from-ipin-cal / from-msilc / from-points) "
                "and pass it with --building"
            )
        return FloorPlan.load(args.plan)
    if is_remote(args.graph):
        return None  # (a wall plan beside a graph in a store: --plan with a local copy)
    beside = Path(args.graph).with_name("floorplan.yaml")
    return FloorPlan.load(beside) if beside.is_file() else None


def check_host(host: str) -> None:
    try:
        socket.getaddrinfo(host, None)
    except (socket.gaierror, UnicodeError):
        raise WorkstationError(f"--host {host}: not an address of this machine") from None


def building_map(args, graph):
    """``--map``'s radio maps merged (quarantined ones refused), in the graph's frame."""
    rm = Fingerprints.merge(read_maps(args.map, False))
    if rm.frame is not None and graph.frame is not None and rm.frame != graph.frame:
        raise WorkstationError(
            f"{', '.join(map(str, args.map))}: the map is in another frame than the graph "
            f"{args.graph}"
        )
    return rm
