"""A walk that matched nothing, turned and scaled onto the building's map
(pipeline/open_by_map.py): the fit on maps whose answer is known, and on ten real mall walks
(tests/data/msilc, MIT)."""

from dataclasses import replace

import numpy as np
import pytest

from tests.pipeline.test_map_prior import AREA, _fix_error, _priors, floor  # noqa: F401
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.run_words import what_the_map_did
from workstation.pipeline.start import resolve_start
from workstation.pipeline.tracking.map_prior import MapPrior
from workstation.pipeline.tracking.open_by_map import fit_open

OPEN_WALK = "5dd9e7c29191"  # matches nothing after its start; its end stays ambiguous


def _open_track(mall):
    g, walks = mall
    s = dict(walks)[OPEN_WALK]
    p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, g)})
    tr = Pipeline(s, g, p).run().track
    assert tr.segments.to_node[-1] == ""  # the stretch after the start is still open
    return g, s, p, tr


def _prior(tr, s, g, deg: float) -> MapPrior:
    """A map that puts the walk's scans where the track has them, turned by ``deg`` about its
    start landmark."""
    t, _, _ = s.wifi.matrix()
    t = t[t > tr.segments.t0[-1]]
    x, y, f = tr.position_at(t, corrected=True)
    n, a = g.node(str(tr.segments.from_node[-1])), np.radians(deg)
    qx, qy = x - n.x, y - n.y
    return MapPrior(t, n.x + np.cos(a) * qx - np.sin(a) * qy,
                    n.y + np.sin(a) * qx + np.cos(a) * qy, f, AREA)  # fmt: skip


@pytest.mark.parametrize("deg", [-20.0, 20.0])
def test_a_turned_map_turns_the_walk_the_same_way(floor, deg):  # noqa: F811
    """A map that has the walk turned by ±20° about its start: the fit turns it the same way — by a little less, the prior (σ 15°) pulling towards the sensors — and its scans end
    nearer to where the map puts them; the scale stays about 1."""
    g, s, p, tr = _open_track(floor)
    prior = _prior(tr, s, g, deg)
    out = fit_open(tr, prior, p.pdr, {n.id: (n.x, n.y, n.floor) for n in g.nodes})
    fit = out.open_fit
    assert fit.scans == prior.t.size >= 10
    assert np.sign(fit.turn_deg) == np.sign(deg) and 0.7 * abs(deg) <= abs(fit.turn_deg) <= abs(deg)
    assert abs(fit.scale - 1.0) <= 0.05

    def off(track):
        x, y, _ = track.position_at(prior.t, corrected=True)
        return np.hypot(x - prior.x, y - prior.y).mean()

    assert off(out) < 0.6 * off(tr)
    assert np.array_equal(out.steps.x, tr.steps.x)  # the forward trajectory stays the sensors'


def test_a_map_that_agrees_or_knows_nothing_moves_nothing(floor):  # noqa: F811
    """The map puts the scans where the track has them, or all in one corner: not decisive,
    the walk stays as the sensors walked it (``open_fit`` says 0°, ×1); with
    ``pdr.map_weight`` 0 the map is not read."""
    g, s, p, tr = _open_track(floor)
    pos = {n.id: (n.x, n.y, n.floor) for n in g.nodes}
    same = _prior(tr, s, g, 0.0)
    corner = MapPrior(same.t, same.x * 0 + 10, same.y * 0 + 10, same.floor, AREA)
    for prior in (same, corner):
        out = fit_open(tr, prior, p.pdr, pos)
        assert (out.open_fit.turn_deg, out.open_fit.scale) == (0.0, 1.0)
        assert np.array_equal(out.steps.x_bc, tr.steps.x_bc)
    off = fit_open(tr, _prior(tr, s, g, 20.0), replace(p.pdr, map_weight=0.0), pos)
    assert off is tr


def test_a_map_that_knows_turns_the_open_walk_onto_its_end(floor):  # noqa: F811
    """With every scan's true place as the map, the walk that matched nothing and whose end
    stayed ambiguous (7.9 m off at its taps) is turned and closes on its end, under 3 m off;
    no walk of the ten is farther from its taps; a walk that matched a landmark after its
    start is never turned (the tracker recalibrated there); the summary says what was done."""
    g, walks = floor
    for name, s in walks:
        p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, g)})
        pipe = Pipeline(s, g, p)
        e0 = _fix_error(pipe.run(), s)
        pipe.prior, _ = _priors(s)
        r = pipe.run()
        assert _fix_error(r, s) <= e0 + 1e-9, name
        fit = r.summary().to_json()["open_by_map"]
        if r.track.detections.matched.any():
            assert fit is None and r.track.open_fit.scans == 0
        if name == OPEN_WALK:
            assert e0 > 6.0 and _fix_error(r, s) < 3.0
            assert fit["turn_deg"] != 0.0 and r.track.end.how == "closed"
            (said,) = what_the_map_did(r.summary())  # run and the panel say it so
            assert f"turned the walk about its start by {fit['turn_deg']:+g}°" in said
        elif fit is not None:
            assert set(fit) == {"turn_deg", "scale", "scans"}


def test_an_end_that_checks_the_walk_outranks_the_map(floor, monkeypatch):  # noqa: F811
    """A walk that matched nothing but whose end closed tightly enough to check it
    (σ ≤ state.END_CHECK_M) keeps the sensors' track, whatever the map says."""
    import workstation.pipeline.tracking.run as tracking

    g, s, p, tr = _open_track(floor)
    ideal, _ = _priors(s)
    assert Pipeline(s, g, p, prior=ideal).run().track.open_fit.turn_deg != 0.0
    closes = tracking.end_on_landmark

    def tight(track, pos):  # the end closes on its landmark with σ 2 m
        closed = closes(track, pos)
        return replace(closed, end=replace(closed.end, node="L113", sigma=2.0, how="closed"))

    monkeypatch.setattr(tracking, "end_on_landmark", tight)
    out = Pipeline(s, g, p, prior=ideal).run().track
    assert out.open_fit.scans == 0 and out.end.sigma == 2.0
