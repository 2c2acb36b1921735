import pytest

from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.sim import simulate


@pytest.fixture(scope="session")
def sim_normal():
    return simulate("office2f", "normal", seed=1, model="ideal")


@pytest.fixture(scope="session")
def sim_varied():
    return simulate("office2f", "varied", seed=1, model="ideal")


@pytest.fixture(scope="session")
def run_normal(sim_normal):
    pipe = Pipeline(sim_normal.session, sim_normal.graph, Params())
    return pipe, pipe.run()
