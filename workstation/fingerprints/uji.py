"""UJIIndoorLoc (Torres-Sospedra et al., IPIN 2014): the standard WiFi fingerprinting benchmark.

Read straight from the distribution zip. Positions are EPSG:3857 metres as published; the
"floor" used for floor recognition is building × 10 + floor, so a hit needs both right.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd

from workstation.errors import InputError
from workstation.fingerprints.localize import Fingerprints, errors, localize
from workstation.fingerprints.matchers import METHODS

NOT_DETECTED = 100


def read_uji(zip_path: str | Path) -> tuple[Fingerprints, Fingerprints]:
    """(training, validation) fingerprints."""
    zip_path = Path(zip_path)
    try:
        zf = zipfile.ZipFile(zip_path)
    except (FileNotFoundError, zipfile.BadZipFile) as e:
        raise InputError(zip_path, f"cannot open the UJIIndoorLoc zip: {e}") from None
    out = []
    with zf:
        for name in ("trainingData.csv", "validationData.csv"):
            member = next((m for m in zf.namelist() if m.endswith(name)), None)
            if member is None:
                raise InputError(zip_path, f"{name} not in the zip")
            df = pd.read_csv(io.BytesIO(zf.read(member)))
            waps = [c for c in df.columns if c.startswith("WAP")]
            rss = df[waps].to_numpy(np.float64)
            rss[rss == NOT_DETECTED] = np.nan
            floor = df["BUILDINGID"].to_numpy(float) * 10 + df["FLOOR"].to_numpy(float)
            out.append(
                Fingerprints(
                    df["LONGITUDE"].to_numpy(float),
                    df["LATITUDE"].to_numpy(float),
                    floor,
                    np.array(waps),
                    rss,
                )
            )
    return out[0], out[1]


def benchmark(zip_path: str | Path) -> list[dict]:
    """Plain 1-NN (raw dBm, unheard = −105, Euclidean), then every method of the matchers'
    table (:mod:`.matchers`) at τ = −90 dBm, the default τ."""
    train, val = read_uji(zip_path)
    rows = []

    def run(name, tau, rss_min, matcher):
        est = localize(train, val, tau=tau, rss_min=rss_min, align_device=False, matcher=matcher)
        e = errors(est, val)
        e_all = np.hypot(est.x - val.x, est.y - val.y)
        rows.append({"method": name, **e, "mean_all_m": round(float(e_all.mean()), 3)})

    run("1-NN raw dBm (unheard −105), Euclidean", -1e9, -105.0, METHODS["1nn"])
    for name, m in METHODS.items():
        run(f"{name}: {m.words()}", -90.0, None, m)
    return rows
