"""Adapters to lagice.Model's component protocols (thermo/model_adapters.py)."""
from types import SimpleNamespace

import numpy as np
import pytest

from forcing import RegularGrid
from lagice.errors import ConfigError
from thermo import (ConstantHealing, FreezingDegreeDayHealing, HealingComponent, ThermoComponent,
                    ThermodynamicHealing, synthetic_air_temperature)

DAY = 86400.0


class FakeMesh:
    """Duck-typed mesh: nodes moved in place like lagice's Lagrangian step."""

    def __init__(self, n=200, seed=0):
        rng = np.random.default_rng(seed)
        self.nodes = rng.uniform(1e5, 9e5, (3 * n, 2))
        self.triangles = np.arange(3 * n).reshape(n, 3)

    def centroids(self):
        return self.nodes[self.triangles].mean(axis=1)

    def areas(self):
        p = self.nodes[self.triangles]
        return 0.5 * ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                      - (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1]))


def state(n=200):
    rng = np.random.default_rng(1)
    A = rng.uniform(0, 1, n)
    return SimpleNamespace(mesh=FakeMesh(n), thickness=A * rng.uniform(0, 2, n), concentration=A,
                           snow=np.zeros(n), damage=rng.uniform(0, 1, n), time_s=0.0)


def test_thermo_component_steps_and_books():
    grid = RegularGrid.from_bbox(0, 1e6, 0, 1e6, spacing_m=50e3)
    air = synthetic_air_temperature(grid, 10 * DAY, seed=0)
    st = state()
    comp = ThermoComponent(air)
    for k in range(20):
        st.mesh.nodes += 100.0  # the mesh moves in place
        rep = comp.step(st, k * 6 * 3600.0, 6 * 3600.0)
        vol = float(np.sum(st.thickness * np.abs(st.mesh.areas())))
        comp.budget.check(vol, rtol=1e-12)
    assert rep["new_ice_m3"] > 0
    meta = comp.checkpoint_meta()
    again = ThermoComponent(air)
    again.load_checkpoint({}, meta)
    assert again.budget.as_dict() == comp.budget.as_dict()


def test_healing_component():
    st = state()
    st.damage[0] = 1.0
    cold = lambda t, x, y: np.full(x.size, -25.0)  # noqa: E731
    warm = lambda t, x, y: np.full(x.size, 2.0)  # noqa: E731
    assert np.all(HealingComponent(ThermodynamicHealing(), warm)(st, 0.0) == 0.0)
    r = HealingComponent(ThermodynamicHealing(), cold)(st, 0.0)
    np.testing.assert_allclose(r, (25.0 - 1.8) / (20.0 * 20 * DAY))
    fdd = HealingComponent(FreezingDegreeDayHealing(), cold, dt_s=3600.0)(st, 0.0)
    assert np.all(np.isfinite(fdd)) and fdd[0] > 0
    assert np.all(HealingComponent(ConstantHealing(1e5))(st, 0.0) == 1e-5)
    with pytest.raises(ConfigError):
        HealingComponent(ThermodynamicHealing())
