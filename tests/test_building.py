"""Building files: floor-plan images georeferenced into the graph's frame (issue #13)."""

import json

import numpy as np
import pytest
from PIL import Image

from tests.conftest import IPIN, REPO, need
from workstation.building import Building, FloorImage
from workstation.building.importers import fit_transform, from_msilc
from workstation.errors import InputError
from workstation.session import load_session
from workstation.viz.plan_image import rerun_transform

MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"

# the competition's reference markers drawn on Map_Floor_-01.png (pixel centres of the dots)
MARKERS_PX = {
    9001: (599.3, 762.1), 9002: (3874.5, 1140.9), 9003: (7465.0, 1141.1), 9004: (7469.0, 1586.4),
    9005: (10388.0, 1583.3), 9006: (10393.4, 3576.6), 9007: (4944.5, 3594.7),
    9008: (605.1, 3588.3), 9999: (4216.3, 2196.0),
}  # fmt: skip


@pytest.mark.shared_data
def test_ipin_cal_puts_the_reference_markers_where_they_are():
    import csv

    from workstation.building.importers import from_ipin_cal
    from workstation.geo import LocalFrame

    sup = need(IPIN / "supplementary")
    frame = LocalFrame(49.461, 11.111)
    img = from_ipin_cal(sup / "calib_mapa_Nuremberg.cal", frame).image(-1)
    with open(sup / "references.csv") as fh:
        ref = {int(r["pointID"]): (float(r["Lat"]), float(r["Lon"])) for r in csv.DictReader(fh)}
    u, v = np.array([MARKERS_PX[i] for i in sorted(MARKERS_PX)]).T
    x, y = img.to_metres(u, v)
    tx, ty = frame.to_xy(*np.array([ref[i] for i in sorted(MARKERS_PX)]).T)
    err = np.hypot(x - tx, y - ty)
    assert err.mean() < 0.6 and err.max() < 1.0, err


def test_msilc_walk_waypoints_fall_on_the_corridors():
    """The bundled Microsoft walk's 13 tapped waypoints land on the walkable (transparent) part
    of its floor image; 57 % of the image is walkable, so 13 by chance is ~0.07 %."""
    b = Building.load(MS / "building.yaml")
    img = b.image(0)
    gt = load_session(MS).ground_truth
    u, v = img.to_pixels(gt.x, gt.y)
    alpha = np.asarray(Image.open(img.path).convert("RGBA"))[..., 3]
    assert (alpha[v.astype(int), u.astype(int)] == 0).all()


def test_msilc_import_spans_the_stated_metres(tmp_path):
    b = from_msilc(MS / "floor_info.json", floor=1)
    c = b.image(1).corners()
    assert c[:, 0].min() == pytest.approx(0) and c[:, 0].max() == pytest.approx(239.8175, abs=1e-3)
    assert c[:, 1].min() == pytest.approx(0) and c[:, 1].max() == pytest.approx(176.4412, abs=1e-3)
    (tmp_path / "bad.json").write_text('{"map_info": {"width": -3}}')
    with pytest.raises(InputError, match="bad.json"):
        from_msilc(tmp_path / "bad.json", MS / "floor_image.png")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_control_points_recover_a_transform(seed):
    rng = np.random.default_rng(seed)
    th, s = rng.uniform(-np.pi, np.pi), rng.uniform(0.01, 0.5)
    c, sn = np.cos(th) * s, np.sin(th) * s
    true = np.array([[c, sn, rng.uniform(-50, 50)], [sn, -c, rng.uniform(-50, 50)]])
    uv = rng.uniform(0, 2000, (5, 2))
    xy = (true @ np.column_stack([uv, np.ones(5)]).T).T
    assert np.allclose(fit_transform(uv[:2], xy[:2]), true, atol=1e-9)  # similarity from two
    noisy = xy + rng.normal(0, 0.05, xy.shape)
    assert np.allclose(fit_transform(uv, noisy)[:, :2], true[:, :2], atol=5e-4)
    with pytest.raises(ValueError):
        fit_transform(uv[:1], xy[:1])
    with pytest.raises(ValueError):
        fit_transform(np.array([[0, 0], [1, 1], [2, 2]]), xy[:3])
    # issue #33: a point at -inf ran 38 minutes; an absurd scale was saved, then refused
    bad = uv[:3].copy()
    bad[2, 0] = -np.inf
    with pytest.raises(ValueError, match="not finite"):
        fit_transform(bad, xy[:3])
    with pytest.raises(ValueError, match="m per pixel"):
        fit_transform(np.array([[0.0, 0.0], [1e-6, 0.0]]), np.array([[0.0, 0.0], [1e4, 0.0]]))
    # issue #55 item 7: three points almost on one line gave an offset of 1.25e9 m
    line = np.array([[0.0, 0.0], [1000.0, 3.0], [2000.0, 5.0]])
    with pytest.raises(ValueError, match="on one line"):
        fit_transform(line, (true @ np.column_stack([line, np.ones(3)]).T).T + [[0, 0], [0, 0.4], [0, 0]])


def test_building_file_round_trips_and_bad_files_name_the_problem(tmp_path):
    b = from_msilc(MS / "floor_info.json", floor=0)
    path = b.save(tmp_path / "building.yaml")
    again = Building.load(path)
    assert np.allclose(again.image(0).transform, b.image(0).transform)
    assert again.image(0).path.resolve() == (MS / "floor_image.png").resolve()
    for text, msg in (
        ("floors: {0: {image: nothere.png, transform: [[1,0,0],[0,-1,0]]}}", "not found"),
        (f"floors: {{0: {{image: {MS / 'floor_image.png'}, transform: [[1,0]]}}}}", "transform"),
        ("floors: {x: {}}", "not a floor number"),
        # issue #33: degenerate or absurd transforms were accepted
        (
            f"floors: {{0: {{image: {MS / 'floor_image.png'}, transform: [[1e-9,0,0],[0,-1e-9,0]]}}}}",
            "m per pixel",
        ),
        (
            f"floors: {{0: {{image: {MS / 'floor_image.png'}, transform: [[1,0,1e300],[0,-1,0]]}}}}",
            "offset",
        ),
        ("floors: {0: {height_m: 1e400}}", "height"),
        ("nme: typo", "unknown key"),
    ):
        (tmp_path / "b.yaml").write_text(text)
        with pytest.raises(InputError, match=msg):
            Building.load(tmp_path / "b.yaml")


def test_display_keeps_thin_lines_and_is_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    a = np.full((3000, 5000, 3), 255, np.uint8)
    a[1500, :] = 0  # a one-pixel line
    Image.fromarray(a).save(tmp_path / "plan.png")
    img = FloorImage(tmp_path / "plan.png", np.array([[0.01, 0, 0], [0, -0.01, 30.0]]))
    rgb, disp = img.display(max_px=1000)
    assert max(rgb.shape[:2]) <= 1000 and (rgb.min(axis=(1, 2)) == 0).any()
    assert np.allclose(disp[:, :2], 5 * img.transform[:, :2])  # display pixels are 5× bigger
    assert list((tmp_path / "cache").rglob("*.npy"))
    again, _ = img.display(max_px=1000)
    assert np.array_equal(again, rgb)


def test_rerun_transform_maps_pixels_to_the_map_frame():
    a = np.array([[0.3, 0.1, 5.0], [0.1, -0.3, 40.0]])
    t, m = rerun_transform(a)
    img = FloorImage(MS / "floor_image.png", a)
    for u, v in ((0, 0), (800, 0), (120, 400)):
        x, y = img.to_metres(u, v)
        p = np.array(m) @ np.array([u, v, 0.0]) + np.array(t)
        assert p[0] == pytest.approx(x) and p[1] == pytest.approx(-y)


def test_a_plan_image_claiming_huge_dimensions_is_refused_before_decoding(tmp_path):
    """Issue #33: a PNG whose header claims 100,000 × 100,000 pixels reached 8.6 GB before a
    MemoryError (Pillow's limit was switched off). Its declared size is refused, naming it."""
    import struct
    import zlib

    from PIL import Image

    from workstation.building import FloorImage

    p = tmp_path / "plan.png"
    Image.new("RGB", (8, 8), "white").save(p)
    data = bytearray(p.read_bytes())
    ihdr = bytearray(data[16:29])  # the IHDR chunk's 13 bytes: width, height, …
    ihdr[0:8] = struct.pack(">II", 100_000, 100_000)
    data[16:29] = ihdr
    data[29:33] = struct.pack(">I", zlib.crc32(b"IHDR" + bytes(ihdr)))
    p.write_bytes(bytes(data))
    img = FloorImage(p, np.array([[0.05, 0.0, 0.0], [0.0, -0.05, 0.0]]))
    with pytest.raises(InputError, match="plan.png") as e:
        img.size()
    assert "pixels" in str(e.value) or "decompression" in str(e.value).lower()
    with pytest.raises(InputError, match="plan.png"):
        img.display(1200)


@pytest.mark.parametrize("width", ["1e30", "1e-9"])
def test_a_floor_info_whose_building_would_not_load_again_is_refused(tmp_path, width):
    """benchmarks/fuzz.py: a floor_info.json 10³⁰ m wide was made into a building file that was
    then refused when read back; now from-msilc refuses it, naming the json."""
    import shutil

    from workstation.building.importers import from_msilc
    from workstation.errors import InputError

    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    shutil.copy(ms / "floor_image.png", tmp_path / "floor_image.png")
    info = tmp_path / "floor_info.json"
    info.write_text(json.dumps({"map_info": {"height": 176.4, "width": float(width)}}))
    with pytest.raises(InputError, match="not a floor plan's") as e:
        from_msilc(info)
    assert str(info) in str(e.value)


@pytest.mark.parametrize("f", [1, 3, 7])
def test_plan_images_are_reduced_a_strip_at_a_time_to_the_same_pixels(tmp_path, monkeypatch, f):
    """Issue #55 item 4: the whole plan was converted to RGBA and floats at once (≈ 37 bytes a
    pixel). Strips of rows give the very pixels the whole image did: each block's darkest, over
    white where transparent — whatever the strip height."""
    from PIL import Image

    import workstation.building.raster as building

    rng = np.random.default_rng(f)
    rgba = rng.integers(0, 256, (517, 1003, 4), dtype=np.uint8)
    rgba[rng.random((517, 1003)) < 0.3, 3] = 0  # transparent
    Image.fromarray(rgba, "RGBA").save(tmp_path / "plan.png")
    whole = building.darkest(rgba, f)  # the image at once, as before
    monkeypatch.setattr(building, "STRIP_PX", 5 * 1003 * f)  # five rows of blocks a strip
    assert np.array_equal(building.downsample(tmp_path / "plan.png", f), whole)
