"""``workstation building``: make a building file from an IPIN .cal, a Microsoft ILC
floor_info.json or control points, and check one."""

from __future__ import annotations

import argparse
from pathlib import Path

from workstation.errors import WorkstationError
from workstation.io.store import local_output


def add_parser(sub) -> None:
    b = sub.add_parser(
        "building", help="building files: floor-plan images georeferenced to the graph"
    )
    bs = b.add_subparsers(dest="building_command", required=True)

    cal = bs.add_parser("from-ipin-cal", help="from an IPIN .cal (images beside it)")
    cal.add_argument("cal", type=Path)
    cal.add_argument("--graph", type=Path, required=True, help="the graph whose frame to use")
    cal.add_argument("-o", "--output", type=local_output, required=True)
    cal.set_defaults(func=_from_cal)

    ms = bs.add_parser(
        "from-msilc", help="from a Microsoft ILC floor_info.json (+ floor_image.png)"
    )
    ms.add_argument("info", type=Path)
    ms.add_argument("--image", type=Path, help="default: floor_image.png beside the json")
    ms.add_argument("--floor", type=float, default=None,
                    help="the floor number it is (default 0, said: the number a Microsoft ILC "
                    "walk is read on)")  # fmt: skip
    ms.add_argument("-o", "--output", type=local_output, required=True)
    ms.set_defaults(func=_from_msilc)

    cp = bs.add_parser(
        "from-points", help="from control points: pixel u,v = metres x,y (two or more)"
    )
    cp.add_argument("image", type=Path)
    cp.add_argument("--floor", type=float, default=0.0)
    cp.add_argument(
        "--point", action="append", required=True, metavar="U,V=X,Y",
        help="a pixel and its position in metres in the graph's frame (repeat)",
    )  # fmt: skip
    cp.add_argument("-o", "--output", type=local_output, required=True, help="created, or a floor added")
    cp.set_defaults(func=_from_points)

    va = bs.add_parser("validate", help="check a building file (and its images)")
    va.add_argument("building", type=Path)
    va.set_defaults(func=_validate)


def _report(b, path: Path) -> None:
    print(f"wrote {path}: {b.name}")
    _describe(b)


def _describe(b) -> None:
    for f, info in sorted(b.floors.items()):
        if info.image is None:
            print(f"  floor {f:g}: no plan image")
            continue
        w, h = info.image.size()
        c = info.image.corners()
        print(
            f"  floor {f:g}: {info.image.path.name} {w}×{h} px, {info.image.metres_per_pixel:.4f} "
            f"m/px, spans x {c[:, 0].min():.1f}…{c[:, 0].max():.1f} m, "
            f"y {c[:, 1].min():.1f}…{c[:, 1].max():.1f} m"
        )


def _from_cal(args) -> int:
    from workstation.building.importers import from_ipin_cal
    from workstation.graph import LandmarkGraph
    g = LandmarkGraph.load(args.graph)
    if g.frame is None:
        raise WorkstationError(
            f"{args.graph}: the graph has no geographic frame to place a .cal in"
        )
    b = from_ipin_cal(args.cal, g.frame)
    _report(b, b.save(args.output))
    return 0


def _from_msilc(args) -> int:
    from workstation.building.importers import from_msilc
    if args.floor is None:  # said, not silent (issue #64 item 7)
        print("note: --floor not given: the plan is floor 0, the floor a Microsoft ILC walk is "
              "read on (give --floor N for another)")  # fmt: skip
    b = from_msilc(args.info, args.image, 0.0 if args.floor is None else args.floor)
    _report(b, b.save(args.output))
    return 0


def _from_points(args) -> int:
    from workstation.building import Building, FloorImage, FloorInfo
    from workstation.building.importers import fit_transform
    uv, xy = [], []
    for p in args.point:
        try:
            a, b = p.split("=")
            u, v = (float(s) for s in a.split(","))
            x, y = (float(s) for s in b.split(","))
        except ValueError:
            raise WorkstationError(
                f"--point {p!r}: write it as U,V=X,Y (pixels = metres)"
            ) from None
        uv.append((u, v))
        xy.append((x, y))
    try:
        t = fit_transform(uv, xy)
    except ValueError as e:
        raise WorkstationError(f"control points: {e}") from None
    img = FloorImage(args.image.resolve(), t)
    img.size()  # a readable image, or a clear error
    new = Building(args.output.stem, {float(args.floor): FloorInfo(None, img)})
    b = Building.load(args.output).merged(new) if args.output.is_file() else new
    _report(b, b.save(args.output))
    if len(uv) > 2:
        mx, my = img.to_metres(*zip(*uv))
        res = [float(((xx - a) ** 2 + (yy - c) ** 2) ** 0.5) for xx, yy, (a, c) in zip(mx, my, xy)]
        print(f"  control point residuals: {', '.join(f'{r:.2f}' for r in res)} m")
    return 0


def _validate(args: argparse.Namespace) -> int:
    from workstation.building import Building
    b = Building.load(args.building)
    print(f"{args.building}: {b.name}, {len(b.floors)} floor(s)")
    _describe(b)
    return 0
