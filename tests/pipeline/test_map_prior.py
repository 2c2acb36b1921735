"""The building's radio map re-ranks the association's chains (pipeline/map_prior.py): the
equation, and on ten real mall walks (tests/data/msilc, MIT) with maps whose answer is known —
one that puts every scan where it was taken, one that puts them all in one corner."""

import math

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.pipeline.tracking.map_prior import MapPrior, loglik
from workstation.session import load_session

DATA = REPO / "tests" / "data" / "msilc"
AREA = 250.0 * 200.0  # about the mall floor's


@pytest.fixture(scope="module")
def floor():
    g = LandmarkGraph.load(DATA / "site1_f1_graph.yaml")
    walks = []
    for f in sorted(DATA.glob("*.txt.gz")):
        s = load_session(f).in_frame(g.frame)
        walks.append((f.name[:12], s))
    assert len(walks) == 10
    return g, walks


def _priors(s):
    """Where an ideal map puts the walk's scans (their true places) and where a map that knows
    nothing puts them (one corner)."""
    gt = s.ground_truth
    t, _, _ = s.wifi.matrix()
    t = t[(t >= gt.t[0]) & (t <= gt.t[-1])]
    x, y, f = gt.at(t)
    return MapPrior(t, x, y, f, AREA), MapPrior(t, x * 0 + 10, y * 0 + 10, f, AREA)


def _fix_error(r, s) -> float:
    gt = s.ground_truth
    m = gt.t >= r.track.start.time
    x, y, _ = r.track.position_at(gt.t[m], corrected=True)
    return float(np.hypot(x - gt.x[m], y - gt.y[m]).mean())


def test_each_scan_adds_the_log_of_its_mixture(floor):
    """Eq. of the module doc: a track that places every scan where the map does scores
    n · log(w / (2πσ²) + (1 − w) / A); on another floor every scan is an outlier."""
    g, walks = floor
    _, s = walks[0]
    p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, g)})
    tr = Pipeline(s, g, p).run().track
    t, _, _ = s.wifi.matrix()
    t = t[t >= tr.start.time]
    x, y, f = tr.position_at(t, corrected=True)
    q = p.pdr
    here = MapPrior(t, x, y, f, AREA)
    one = q.map_inlier / (2 * math.pi * q.map_sigma_m**2) + (1 - q.map_inlier) / AREA
    assert loglik(tr, here, q) == pytest.approx(t.size * math.log(one))
    away = MapPrior(t, x + 3 * q.map_sigma_m, y, f, AREA)
    assert loglik(tr, away, q) < loglik(tr, here, q)
    upstairs = MapPrior(t, x, y, f + 1, AREA)
    assert loglik(tr, upstairs, q) == pytest.approx(t.size * math.log((1 - q.map_inlier) / AREA))


def test_a_map_that_knows_chooses_the_right_chain_and_one_that_does_not_changes_nothing(floor):
    """With every scan's true place as the map, the walk whose sensors' best chain is wrong
    (5dd9e7bf…, 6.4 m off at its fixes) gets the right one; no walk gets worse; a map putting
    every scan in one corner changes no walk; with ``pdr.map_weight`` 0 the map is not read."""
    g, walks = floor
    changed = []
    for name, s in walks:
        p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, g)})
        ideal, corner = _priors(s)
        pipe = Pipeline(s, g, p)
        r0 = pipe.run()
        e0 = _fix_error(r0, s)
        assert r0.summary().to_json()["chain_by_map"] is None
        pipe.prior = ideal
        r1 = pipe.run()
        assert _fix_error(r1, s) <= e0 + 1e-9
        if r1.track.map_rerank.rank:
            changed.append((name, e0, _fix_error(r1, s)))
            assert r1.summary().to_json()["chain_by_map"]["rank"] == r1.track.map_rerank.rank
        pipe.prior = corner
        r2 = pipe.run()
        assert r2.track.map_rerank.rank == 0
        assert np.array_equal(r2.track.steps.x_bc, r0.track.steps.x_bc)
        off = Pipeline(s, g, p.updated(**{"pdr.map_weight": 0.0}), prior=ideal).run()
        assert (
            np.array_equal(off.track.steps.x_bc, r0.track.steps.x_bc)
            and off.track.map_rerank.chains == 0
        )
    assert [c[0] for c in changed] == ["5dd9e7bf9191"]
    assert changed[0][1] > 5.0 and changed[0][2] < 3.0


def test_the_start_is_never_the_maps(floor):
    """Start inferred: a map that knows where every scan was taken changes neither the start
    nor its candidates and margin (the quarantine stays the sensors')."""
    g, walks = floor
    for _, s in walks[:4]:
        ideal, _ = _priors(s)
        a = Pipeline(s, g, Params()).run().track
        b = Pipeline(s, g, Params(), prior=ideal).run().track
        assert (a.start.node, a.start.candidates) == (b.start.node, b.start.candidates)
