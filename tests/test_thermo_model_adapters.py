"""The thermodynamics and healing components of lagice.Model (thermo/model_adapters.py),
on a real mesh and state."""
import numpy as np
import pytest

from forcing import RegularGrid
from lagice.budget import VolumeLedger
from lagice.errors import ConfigError
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.state import IceState
from thermo import (
    ConstantHealing,
    FreezingDegreeDayHealing,
    HealingComponent,
    ThermoComponent,
    ThermodynamicHealing,
    synthetic_air_temperature,
)

DAY = 86400.0


def state(seed=1):
    poly, _ = rectangle_domain(800e3, 800e3, 1e5, 1e5)
    mesh = generate_mesh(poly, 60e3)
    rng = np.random.default_rng(seed)
    n = mesh.n_elements
    A = rng.uniform(0, 1, n)
    st = IceState.uniform(mesh, thickness_m=A * rng.uniform(0, 2, n), concentration=A,
                          damage=rng.uniform(0, 0.99, n), cohesion_pa=2e4)
    st.snow = np.zeros(n)
    return st


def test_thermo_component_steps_and_books_into_the_ledger():
    grid = RegularGrid.from_bbox(0, 1e6, 0, 1e6, spacing_m=50e3)
    air = synthetic_air_temperature(grid, 10 * DAY, seed=0)
    st = state()
    comp = ThermoComponent(air)
    ledger = VolumeLedger(st.ice_volume_m3)
    for k in range(20):
        st.mesh.nodes[:] += 100.0  # the mesh moves in place (the weights must follow)
        rep = comp.step(st, k * 6 * 3600.0, 6 * 3600.0, ledger)
        assert abs(ledger.budget(st.ice_volume_m3)["relative_residual"]) < 1e-12
    assert rep["new_ice_m3"] > 0
    parts = sum(comp.totals_m3[k] for k in ("congelation", "new_ice", "floor_removed"))
    assert parts == pytest.approx(ledger.total("thermo"), rel=1e-12)
    arrays, meta = comp.checkpoint_state()
    again = ThermoComponent(air)
    again.restore(arrays, meta)
    assert again.totals_m3 == comp.totals_m3


def test_healing_component():
    st = state()
    st.damage[0] = 0.999999
    cold = lambda t, x, y: np.full(x.size, -25.0)  # noqa: E731
    warm = lambda t, x, y: np.full(x.size, 2.0)  # noqa: E731
    assert np.all(HealingComponent(ThermodynamicHealing(), warm).rate(st, 0.0) == 0.0)
    r = HealingComponent(ThermodynamicHealing(), cold).rate(st, 0.0)
    np.testing.assert_allclose(r, (25.0 - 1.8) / (20.0 * 20 * DAY))
    fdd = HealingComponent(FreezingDegreeDayHealing(), cold, dt_s=3600.0).rate(st, 0.0)
    assert np.all(np.isfinite(fdd)) and fdd[0] > 0
    assert np.all(HealingComponent(ConstantHealing(1e5)).rate(st, 0.0) == 1e-5)
    with pytest.raises(ConfigError):
        HealingComponent(ThermodynamicHealing())
