import numpy as np
import pytest

from workstation.baselines.particles import particle_filter
from workstation.baselines.pdr import pdr
from workstation.baselines.tap import tap_interpolation
from workstation.fingerprints.localize import Fingerprints
from workstation.pipeline import Pipeline
from workstation.sim import simulate


@pytest.fixture(scope="module")
def office():
    sim = simulate("office2f", "normal", 1, model="ideal")
    res = Pipeline(sim.session, sim.graph).run()
    return sim, res


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_baselines_rank_as_in_the_paper(seed):
    """Ours, map filtering, PDR I (compass), PDR II (gyro): the paper's order on three walks,
    each its own noise (issue #31: seed 1 alone; seeds 1–4 give 0.23–0.33, 4.7–5.1, 5.2–5.5 and
    6.8–23 m)."""
    sim = simulate("office2f", "normal", seed, model="ideal")
    res = Pipeline(sim.session, sim.graph).run()
    s, g = sim.session, sim.graph
    st = g.node("W0")
    floors = np.array(g.floors)
    ours = res.summary(s, g).to_json()["trajectory_error_mean_m"]
    pdr1 = pdr(s, (st.x, st.y), st.floor, "compass", known_floors=floors).errors(s).mean()
    pdr2 = pdr(s, (st.x, st.y), st.floor, "gyro", known_floors=floors).errors(s).mean()
    mf = (
        particle_filter(s, sim.plan, (st.x, st.y), st.floor, n=200, seed=1, known_floors=floors)
        .errors(s)
        .mean()
    )
    assert ours < 0.71 < mf < pdr1 < pdr2
    tap = tap_interpolation(s, res.steps.t, g).errors(s).mean()
    assert tap < 1.0


def test_zee_starts_anywhere_and_smooths(office):
    sim, _ = office
    s = sim.session
    tr = particle_filter(
        s, sim.plan, None, 0.0, n=1000, seed=2, smooth=True, known_floors=np.array([0.0, 1.0])
    )
    assert tr.t.size > 400 and np.isfinite(tr.x).all()
    e = tr.errors(s)
    assert np.median(e[-100:]) < np.median(e[:20]) + 20  # it does not run away


def test_baseline_radio_maps_place_every_scan(office):
    sim, _ = office
    s = sim.session
    st = sim.graph.node("W0")
    rm = pdr(s, (st.x, st.y), 0.0, "compass").radio_map(s)
    assert len(rm) >= s.wifi.n_scans - 5
    survey = Fingerprints.from_session(simulate("office2f", "survey5", 1, model="ideal").session)
    assert len(survey) == 5 * 222
