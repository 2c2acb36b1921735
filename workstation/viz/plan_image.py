"""Floor-plan images of a building file, drawn under the map: in Rerun as an encoded image with
its pixel → metres transform (the map's 2-D views draw y = −north), in viser as a textured
plane. The image is downsampled and cached once (:meth:`workstation.building.FloorImage.display`),
encoded once here, never per frame."""

from __future__ import annotations

import io
from functools import lru_cache

import numpy as np

from workstation.building import Building, FloorImage
from workstation.fingerprints.quality import quality
from workstation.viz.colours import coverage_rgb, rss_rgb


def encoded(image: FloorImage) -> tuple[bytes, np.ndarray, tuple[int, int]]:
    """(PNG bytes of the display image, its pixel → metres transform, (width, height))."""
    return _encoded(image.path, image.transform.tobytes())


@lru_cache(maxsize=16)
def _encoded(path, transform_bytes) -> tuple[bytes, np.ndarray, tuple[int, int]]:
    from PIL import Image

    t = np.frombuffer(transform_bytes, dtype=float).reshape(2, 3)
    rgb, disp = FloorImage(path, t).display()
    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG", optimize=False)
    return buf.getvalue(), disp, (rgb.shape[1], rgb.shape[0])


def log_plan_images(rec, building: Building | None, floor_path, opacity: float = 0.8) -> list[str]:
    """Log each floor's plan image under ``/map/<floor>/plan/image``; returns the entity paths."""
    out: list[str] = []
    if building is None:
        return out
    for f, info in sorted(building.floors.items()):
        if info.image is None:
            continue
        path = f"/map/{floor_path(f)}/plan/image"
        log_plan_image(rec, path, info.image, opacity)
        out.append(path)
    return out


def log_plan_image(rec, path: str, image: FloorImage, opacity: float = 0.8) -> None:
    """One plan image at ``path`` (static), placed in metres by its own transform."""
    import rerun as rr

    png, a, _ = encoded(image)
    translation, mat = rerun_transform(a)
    rec.log(path, rr.Transform3D(translation=translation, mat3x3=mat), static=True)
    rec.log(
        path,
        rr.EncodedImage(contents=png, media_type="image/png", opacity=opacity, draw_order=-100.0),
        static=True,
    )


def rerun_transform(a: np.ndarray) -> tuple[list[float], list[list[float]]]:
    """(translation, 3 × 3 matrix) taking display pixels (u, v) to the map's (x, −y): the map's
    2-D views draw north up with their y axis pointing down."""
    mat = [[a[0, 0], a[0, 1], 0.0], [-a[1, 0], -a[1, 1], 0.0], [0.0, 0.0, 1.0]]
    return [float(a[0, 2]), float(-a[1, 2]), 0.0], [[float(v) for v in r] for r in mat]


def viser_pose(a: np.ndarray, size: tuple[int, int]) -> tuple[float, float, tuple, float]:
    """(centre x, centre y, width m, height m, rotation about z) of a display image whose pixel →
    metres transform ``a`` is a similarity (rotation, scale, a y flip); viser draws an image as a
    plane centred on its position, +u along +x and rows along +y before rotation (the caller
    flips the rows)."""
    w, h = size
    cx = a[0, 0] * w / 2 + a[0, 1] * h / 2 + a[0, 2]
    cy = a[1, 0] * w / 2 + a[1, 1] * h / 2 + a[1, 2]
    sx = float(np.hypot(a[0, 0], a[1, 0]))
    sy = float(np.hypot(a[0, 1], a[1, 1]))
    theta = float(np.arctan2(a[1, 0], a[0, 0]))
    return float(cx), float(cy), (sx * w, sy * h), theta


def log_quality(rec, fp, graph, floor_path, n_aps: int = 5) -> list[str]:
    """The radio map's quality under ``/map/<floor>/quality/``: the coverage map (distance to
    the nearest reference point, 0 m yellow … 10 m and more purple) and the strongest APs' RSS
    heatmaps (``ap/<bssid>``, within ``quality.FIELD_REACH_M`` of a point), one dot per walkable
    cell of the grid, in metres under the map (dots rather than an image: only walkable cells
    are drawn, nothing hides the walls)."""
    import rerun as rr

    out: list[str] = []
    if fp is None or not len(fp):
        return out
    for f, q in quality(fp, graph, n_aps=n_aps).items():
        xs, ys = q.centres()
        gx, gy = np.meshgrid(xs, ys)
        layers = [("coverage", q.mask, coverage_rgb(q.coverage_m[q.mask]))]
        rss = q.rss if q.rss is not None else ()  # fields only where APs were asked for
        for b, field in zip(q.bssids, rss):
            m = q.mask & np.isfinite(field)  # a field ends FIELD_REACH_M from the points
            layers.append((f"ap/{str(b).replace(':', '')}", m, rss_rgb(field[m])))
        for name, m, rgb in layers:
            rgba = np.column_stack([rgb, np.full(len(rgb), 150, np.uint8)])
            path = f"/map/{floor_path(f)}/quality/{name}"
            pos = np.column_stack([gx[m], -gy[m]])
            rec.log(
                path,
                rr.Points2D(pos, colors=rgba, radii=[0.55 * q.cell_m], draw_order=-50.0),
                static=True,
            )
            out.append(path)
    return out
