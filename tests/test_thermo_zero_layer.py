"""Zero-layer thermodynamics (thermo/zero_layer.py): Stefan's law, budget, floor booking."""
import numpy as np
import pytest

from lagice.errors import ConfigError, LagiceError
from thermo import ThermoParams, VolumeBudget, ZeroLayerThermo, build

DAY = 86400.0


@pytest.mark.parametrize("h0, dt", [(0.5, 3600.0), (0.1, 6 * 3600.0), (1.5, 1800.0)])
def test_stefan_growth_constant_cold(h0, dt):
    p = ThermoParams()
    z = ZeroLayerThermo(p)
    ta = -25.0
    h = np.array([h0])
    A = np.array([1.0])
    n = int(30 * DAY / dt)
    for k in range(1, n + 1):
        z.step(h, A, ta, dt)
        t = k * dt
        stefan = np.sqrt(h0**2 + 2 * p.conductivity_ice_w_m_k * (p.freezing_point_c - ta) * t
                         / (p.rho_ice_kg_m3 * p.latent_heat_j_kg))
        assert abs(h[0] / stefan - 1.0) < 1e-2
    assert h[0] > h0 + 0.2
    assert A[0] == 1.0


def test_melt_snow_insulation_and_open_water():
    z = ZeroLayerThermo()
    # warm: melts; thin ice melts completely and is booked as congelation < 0
    h = np.array([1.0, 0.02])
    A = np.array([1.0, 1.0])
    tend = z.step(h, A, 3.0, DAY)
    assert h[0] < 1.0 and tend.congelation[0] < 0
    assert h[1] == 0.0 and A[1] == 0.0 and tend.total[1] == -0.02
    # snow insulates: slower growth
    h = np.array([0.5, 0.5])
    A = np.ones(2)
    hs = np.array([0.0, 0.3])
    z.step(h, A, -20.0, DAY, hs=hs)
    assert h[1] < h[0]
    # open water: new ice at h0 thickness raises A
    h = np.array([0.0])
    A = np.array([0.0])
    tend = z.step(h, A, -20.0, 3600.0)
    p = z.params
    rho_l = p.rho_ice_kg_m3 * p.latent_heat_j_kg
    dv = p.open_water_heat_transfer_w_m2_k * (p.freezing_point_c + 20.0) * 3600.0 / rho_l
    assert tend.new_ice[0] == pytest.approx(dv)
    assert A[0] == pytest.approx(dv / p.new_ice_thickness_m)
    # warm air over open water: nothing
    h = np.array([0.0])
    A = np.array([0.0])
    assert z.step(h, A, 5.0, DAY).total[0] == 0.0


def test_thin_ice_floor_booked():
    p = ThermoParams(min_ice_thickness_m=0.05, min_concentration=1e-3)
    z = ZeroLayerThermo(p)
    # thin ice compacts: volume kept, area shrinks to h/h_min
    h = np.array([0.02])
    A = np.array([1.0])
    tend = z.step(h, A, -1.8, 1.0)  # Ta = Tf: no growth
    assert h[0] == 0.02 and A[0] == pytest.approx(0.4) and tend.total[0] == 0.0
    # a trace of ice below min_concentration·h_min is removed and booked
    h = np.array([1e-5])
    A = np.array([0.5])
    hs = np.array([1e-6])
    tend = z.step(h, A, -1.8, 1.0, hs=hs)
    assert h[0] == 0.0 and A[0] == 0.0 and hs[0] == 0.0
    assert tend.floor_removed[0] == -1e-5 and tend.total[0] == -1e-5 and tend.snow_removed[0] == -1e-6


def test_volume_budget_closes_with_melt_growth_new_ice_and_outflow():
    rng = np.random.default_rng(5)
    n = 3000
    area = rng.uniform(1e6, 1e8, n)
    A = rng.uniform(0.0, 1.0, n)
    A[rng.uniform(size=n) < 0.1] = 0.0
    A[rng.uniform(size=n) < 0.2] = 1.0
    h = A * rng.uniform(0.0, 3.0, n)
    h[A == 0] = 0.0
    hs = A * rng.uniform(0.0, 0.4, n)
    budget = VolumeBudget.from_state(h, area)
    z, _ = build(thermodynamics=True)
    dt = 6 * 3600.0
    x = rng.uniform(0, 1, n)
    kinds = set()
    for step in range(240):  # 60 days: cold spells, melt, freeze-up
        ta = -12.0 + 14.0 * np.sin(2 * np.pi * step / 80.0) + 3.0 * (x - 0.5) + rng.normal(0, 2.0, n)
        tend = z.step(h, A, ta, dt, hs=hs, budget=budget, area_m2=area)
        np.testing.assert_allclose(tend.congelation + tend.new_ice + tend.floor_removed, tend.total,
                                   atol=1e-15)
        kinds |= {k for k, arr in (("grow", tend.congelation > 0), ("melt", tend.congelation < 0),
                                   ("new", tend.new_ice > 0), ("floor", tend.floor_removed < 0)) if arr.any()}
        if step % 40 == 39:  # ice leaving through an open boundary
            gone = rng.uniform(size=n) < 0.02
            budget.book_outflow(float(np.sum(h[gone] * area[gone])))
            h[gone] = 0.0
            A[gone] = 0.0
            hs[gone] = 0.0
        vol = float(np.sum(h * area))
        assert budget.check(vol, rtol=1e-12) <= 1e-12
        assert np.all((A >= 0) & (A <= 1) & (h >= 0))
    assert {"grow", "melt", "new"} <= kinds
    assert budget.outflow_m3 > 0 and budget.new_ice_m3 > 0 and budget.congelation_m3 != 0
    with pytest.raises(LagiceError, match="budget"):
        budget.check(vol * (1 + 1e-9), rtol=1e-12)


def test_params_and_build():
    with pytest.raises(ConfigError):
        ThermoParams(conductivity_ice_w_m_k=-1.0)
    with pytest.raises(ConfigError):
        ThermoParams().replace(nonsense=1.0)
    with pytest.raises(ConfigError):
        ThermoParams(new_ice_thickness_m=0.01, min_ice_thickness_m=0.05)
    assert build() == (None, None)
    z, heal = build(thermodynamics=True, healing="thermodynamic")
    assert isinstance(z, ZeroLayerThermo) and heal is not None
    with pytest.raises(ConfigError):
        ZeroLayerThermo().step(np.zeros(3), np.zeros(4), -5.0, 10.0)
    rate = ZeroLayerThermo().growth_rate(1.0, -21.8)
    assert rate == pytest.approx(2.0 * 20.0 / (900.0 * 3.34e5))


def test_parallel_kernel_matches_serial(monkeypatch):
    import forcing._numba_util as nu

    rng = np.random.default_rng(1)
    n = 1000
    A0 = rng.uniform(0, 1, n)
    h0 = A0 * rng.uniform(0, 2, n)
    ta = rng.uniform(-30, 5, n)
    h1, A1 = h0.copy(), A0.copy()
    t1 = ZeroLayerThermo().step(h1, A1, ta, 3600.0)
    monkeypatch.setattr(nu, "PARALLEL_MIN_SIZE", 0)
    h2, A2 = h0.copy(), A0.copy()
    t2 = ZeroLayerThermo().step(h2, A2, ta, 3600.0)
    np.testing.assert_array_equal(h1, h2)
    np.testing.assert_array_equal(A1, A2)
    np.testing.assert_array_equal(t1.total, t2.total)
