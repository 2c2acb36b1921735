"""Device RSS offsets (workstation/fingerprints/devices.py) on synthetic walks with known offsets."""

import numpy as np
import pytest

from workstation.fingerprints.devices import ap_means, fit_offsets, offset_against
from workstation.fingerprints.localize import Fingerprints, localize


def _walk(rng, level, offset, n=60, heard=0.6, noise=4.0):
    """Scans of one walk: each AP heard with probability ``heard``, RSS = level + offset + noise."""
    rss = level[None, :] + offset + rng.normal(0, noise, (n, level.size))
    rss[rng.random(rss.shape) > heard] = np.nan
    return rss


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_median_polish_recovers_per_walk_offsets(seed):
    rng = np.random.default_rng(seed)
    level = rng.uniform(-90, -45, 40)
    true = np.array([0.0, 6.5, -3.0, 2.0])
    means = np.vstack([ap_means(_walk(rng, level, o)) for o in true])
    off, lev = fit_offsets(means)
    # offsets are known up to a common shift: compare differences (noise 4 dB / √36 per AP)
    assert np.abs((off - off[0]) - (true - true[0])).max() < 1.0
    assert abs(np.median(off)) < 1e-9


def test_too_few_shared_aps_give_no_offset():
    assert offset_against(np.array([-60.0, -70, np.nan]), np.array([-50.0, -60, -40])) == 0.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_localize_removes_the_query_phones_offset(seed):
    """A map on a grid; queries from the same spots read 8 dB high: with the offset removed the
    errors match the unshifted queries', without it they grow."""
    rng = np.random.default_rng(seed)
    xy = np.array([(x, y) for x in range(0, 40, 2) for y in range(0, 10, 2)], float)
    aps = rng.uniform([0, 0], [40, 10], (25, 2))
    d = np.hypot(xy[:, None, 0] - aps[None, :, 0], xy[:, None, 1] - aps[None, :, 1])
    rss = -40 - 25 * np.log10(1 + d)
    bss = np.array([f"ap{i}" for i in range(25)])
    floor = np.zeros(len(xy))
    ref = Fingerprints(xy[:, 0], xy[:, 1], floor, bss, rss + rng.normal(0, 2, rss.shape))
    q = Fingerprints(xy[:, 0], xy[:, 1], floor, bss, rss + rng.normal(0, 2, rss.shape))
    base = localize(ref, q)
    est = localize(ref, q.shifted(8.0))
    raw = localize(ref, q.shifted(8.0), align_device=False)
    err = lambda e: np.hypot(e.x - q.x, e.y - q.y).mean()  # noqa: E731
    assert est.device_offset_db == pytest.approx(8.0, abs=1.0)
    assert err(est) <= err(base) + 0.5
    assert err(raw) > err(est) + 0.5


def test_merge_aligns_walks_and_reports_their_offsets():
    rng = np.random.default_rng(3)
    level = rng.uniform(-90, -45, 30)
    bss = np.array([f"ap{i}" for i in range(30)])
    maps = []
    for o in (0.0, 7.0, 0.0):
        r = _walk(rng, level, o, n=40)
        maps.append(Fingerprints(np.zeros(40), np.zeros(40), np.zeros(40), bss, r))
    m = Fingerprints.merge(maps, align_devices=True)
    assert m.offsets_db[1] - m.offsets_db[0] == pytest.approx(7.0, abs=1.0)
    assert Fingerprints.merge(maps).offsets_db == ()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_walks_of_one_phone_model_are_merged_as_read(seed):
    """Offsets are a property of the phone model: walks of one model are merged as they read
    (their per-walk 'offsets' would be coverage differences); across models, or with a model
    unknown, each walk's offset is fitted and removed."""
    rng = np.random.default_rng(seed)
    level = rng.uniform(-90, -45, 30)
    bss = np.array([f"ap{i}" for i in range(30)])

    def maps(models):
        out = []
        for o, model in zip((0.0, 7.0, 0.0), models):
            r = _walk(rng, level, o, n=40)
            z = np.zeros(40)
            out.append(Fingerprints(z, z, z, bss, r, device=model))
        return out

    same = Fingerprints.merge(maps(["SM-G960F"] * 3), align_devices=True)
    assert same.offsets_db == () and same.device == "SM-G960F"
    for models in (["SM-G960F", "SM-A520F", "SM-G960F"], ["SM-G960F", "", "SM-G960F"]):
        m = Fingerprints.merge(maps(models), align_devices=True)
        assert m.device == ""
        assert m.offsets_db[1] - m.offsets_db[0] == pytest.approx(7.0, abs=1.0)


def test_a_run_radio_map_says_its_phone_model(tmp_path):
    """radiomap.csv carries the walk's phone model (``# device:``) for merge and localize."""
    from workstation.export import write_radiomap

    cols = {"x": np.array([1.0]), "y": np.array([2.0]), "floor": np.array([0.0]),
            "ap1": np.array([-60.0])}  # fmt: skip
    p = write_radiomap(cols, tmp_path / "radiomap.csv", device="SM-G960F")
    assert Fingerprints.read(p).device == "SM-G960F"
    p2 = write_radiomap(cols, tmp_path / "other.csv")
    assert Fingerprints.read(p2).device == ""
