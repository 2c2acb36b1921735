"""The building file: per floor, an optional raster floor plan georeferenced into the metric
frame the landmark graph uses, and the floor's height. YAML beside the graph::

    name: museum
    frame: {origin_lat: 49.461, origin_lon: 11.111}   # the graph's frame (optional)
    floors:
      -1:
        height_m: -3.1                                # optional
        image: Map_Floor_-01.png                      # relative to this file
        transform: [[a, b, c], [d, e, f]]             # pixel (u, v) → metres: x = a u + b v + c

Pixel (0, 0) is the top-left corner of the image. Made from an IPIN ``.cal``, a Microsoft ILC
``floor_info.json`` or control points by :mod:`.importers`. Large images are downsampled
for display once and cached (:mod:`.raster`). Beside it: the floor plan's walls
(:mod:`.floorplan`) and the checks that a walk, a graph and a building belong together
(:mod:`.consistency`).
"""

from workstation.building import png_strips
from workstation.building.model import (
    DISPLAY_PX,
    MAX_CAL_FLOORS,
    MAX_COORD,
    MAX_FLOOR,
    MAX_SCALE,
    MIN_SCALE,
    Building,
    FloorImage,
    FloorInfo,
    check_transform,
    is_file,
)
from workstation.building.raster import MAX_PIXELS

__all__ = ["DISPLAY_PX", "MAX_CAL_FLOORS", "MAX_COORD", "MAX_FLOOR", "MAX_PIXELS", "MAX_SCALE",
           "MIN_SCALE", "Building", "FloorImage", "FloorInfo", "check_transform", "is_file",
           "png_strips"]  # fmt: skip
