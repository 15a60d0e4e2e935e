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


def test_new_ice_is_undamaged_and_keeps_the_damaged_ice_area():
    """thermo.new_ice_undamaged (neXtSIM-DG's lateral-growth healing): where new ice raises the
    concentration from A to A', d becomes d A/A', so the damaged area sum(d A a) is unchanged by a
    cold step, while the default leaves d and lets the damaged area grow with A. Elements whose
    concentration did not grow keep their damage bit for bit; the report and the running total
    add up the damage removed, and a checkpoint carries the total."""
    cold = lambda t, x, y: np.full(x.size, -30.0)  # noqa: E731
    runs = {}
    for flag in (False, True):
        st = state()
        st.concentration[:5] = 0.0  # open water: its new ice must be undamaged
        st.thickness[:5] = 0.0
        st.concentration[5:10] = 1.0  # full: nothing grows, the damage stays
        area = np.abs(st.mesh.areas())
        comp = ThermoComponent(cold, new_ice_undamaged=flag)
        d0, a0 = st.damage.copy(), st.concentration.copy()
        rep = comp.step(st, 0.0, 6 * 3600.0)
        grew = st.concentration > a0
        assert grew.sum() > 0.5 * st.mesh.n_elements  # most elements have open water that freezes
        runs[flag] = (st, d0, a0, grew, area, rep, comp)
    st, d0, a0, grew, area, rep, comp = runs[True]
    assert np.sum(st.damage * st.concentration * area) == pytest.approx(np.sum(d0 * a0 * area), rel=1e-12)
    np.testing.assert_allclose(st.damage[grew], d0[grew] * a0[grew] / st.concentration[grew], rtol=1e-15)
    assert np.all(st.damage[:5] == 0.0) and np.all(st.concentration[:5] > 0.0)
    assert np.array_equal(st.damage[~grew], d0[~grew]) and np.array_equal(st.damage[5:10], d0[5:10])
    removed = np.sum((d0 - st.damage) * area)
    assert removed > 0 and rep["damage_diluted_by_new_ice_m2"] == pytest.approx(removed, rel=1e-12)
    assert comp.damage_diluted_m2 == rep["damage_diluted_by_new_ice_m2"]
    again = ThermoComponent(cold, new_ice_undamaged=True)
    again.restore(*comp.checkpoint_state())
    assert again.damage_diluted_m2 == comp.damage_diluted_m2
    off, d0_off, a0_off, _, area_off, rep_off, _ = runs[False]
    assert np.array_equal(off.damage, d0_off) and "damage_diluted_by_new_ice_m2" not in rep_off
    assert np.sum(off.damage * off.concentration * area_off) > 1.01 * np.sum(d0_off * a0_off * area_off)
    # the two runs differ only in the damage
    assert np.array_equal(off.concentration, st.concentration) and np.array_equal(off.thickness, st.thickness)
    with pytest.raises(ConfigError, match="new_ice_undamaged"):
        ThermoComponent(cold, new_ice_undamaged=1)


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


def test_thermodynamic_effective_rate_is_the_numpy_form_bit_for_bit():
    # the compiled pass replaces apply() on a copy divided by dt: the same values to the bit,
    # warm and cold air, undamaged ice, ice that heals to 0 within the step, a NaN air temperature
    from thermo.healing import Healing

    rng = np.random.default_rng(3)
    n = 5000
    ta = rng.uniform(-45.0, 5.0, n)
    ta[:20] = -1.8  # exactly at freezing: rate 0
    ta[20] = np.nan
    d = rng.uniform(0.0, 1.0, n) ** 3
    d[30:60] = 0.0
    d[60:90] = 1e-9  # heals to the floor within the step
    ta[60:90] = -30.0
    law = ThermodynamicHealing(th0_s=3.0 * DAY, delta_t0_k=17.0)
    before = d.copy()
    for dt in (600.0, 3600.0, 2.5 * DAY):
        got = law.effective_rate(ta, d, dt)
        want = Healing.effective_rate(law, ta, d, dt)
        np.testing.assert_array_equal(got, want)
        assert np.isnan(got[20]) and np.all(got[:20] == 0.0) and np.all(got[30:60] == 0.0)
        np.testing.assert_allclose(got[60:90] * dt, d[60:90], rtol=1e-15)  # floored: the damage there
    np.testing.assert_array_equal(d, before)  # the damage is not touched
    with pytest.raises(ConfigError, match="dt_s"):
        law.effective_rate(ta, d, 0.0)


class _CountingAir:
    """A scalar field that counts its evaluations (a real Field, wrapped)."""

    def __init__(self):
        from forcing.base import SCALAR, CallableField

        self.calls = 0

        def f(t, x, y):
            self.calls += 1
            return -20.0 + 1e-6 * x - 2e-6 * y + 1e-5 * t

        self.field = CallableField(f, SCALAR, "degC")


def test_thermodynamics_and_healing_share_one_air_temperature_evaluation():
    # in a step the thermodynamics takes the air temperature at t + dt on the moved mesh, and
    # the next step's healing rate at its start: the same time and centroids, so one
    # evaluation serves both; moving nodes, another time or another mesh evaluates again
    from thermo.model_adapters import air_at_centroids

    air = _CountingAir()
    st = state()
    thermo = ThermoComponent(air.field)
    heal = HealingComponent(ThermodynamicHealing(), air.field, dt_s=600.0)
    memo = air_at_centroids(air.field)
    assert thermo._air is memo and heal._air is memo
    c = st.mesh.centroids()
    expect = -20.0 + 1e-6 * c[:, 0] - 2e-6 * c[:, 1] + 1e-5 * 600.0
    thermo.step(st, 600.0, 600.0)
    assert air.calls == 1
    r = heal.rate(st, 600.0)
    assert air.calls == 1 and memo.n_reused == 1
    np.testing.assert_array_equal(r, ThermodynamicHealing().effective_rate(expect, st.damage, 600.0))
    heal.rate(st, 1200.0)  # another time
    assert air.calls == 2
    st.mesh.nodes[5] += 1.0  # nodes moved in place
    heal.rate(st, 1200.0)
    assert air.calls == 3
    heal.rate(st, 1200.0)
    assert air.calls == 3
    from lagice.mesh import Mesh

    m = st.mesh
    st.mesh = Mesh(m.nodes.copy(), m.triangles.copy(), m.boundary_edges, m.boundary_tags, m.tag_names)
    heal.rate(st, 1200.0)  # a new mesh (a remesh, a checkpoint load): evaluated again
    assert air.calls == 4 and memo.n_evaluations == 4
    # the memo lives on the field: nothing keeps a field (and the mesh in its memo) alive
    import gc
    import weakref

    gone = weakref.ref(air.field)
    del thermo, heal, memo, air
    gc.collect()
    assert gone() is None


def test_nextsim_healing_shares_the_air_temperature_with_the_thermodynamics():
    # the flagship's healing law (neXtSIM's, lagice.strength) takes its air temperature through
    # the same centroid memo: after the thermodynamics' evaluation at the same time on the same
    # mesh it evaluates nothing, and its rate is the one a fresh evaluation gives, bit for bit
    from lagice.strength import NextsimHealing, NextsimHealingComponent
    from thermo.model_adapters import air_at_centroids

    air = _CountingAir()
    st = state()
    thermo = ThermoComponent(air.field)
    heal = NextsimHealingComponent(NextsimHealing(air.field))
    thermo.step(st, 600.0, 600.0)
    r = heal.rate(st, 600.0)
    assert air.calls == 1 and air_at_centroids(air.field).n_reused == 1
    c = st.mesh.centroids()
    fresh = air.field.evaluate(600.0, np.ascontiguousarray(c[:, 0]), np.ascontiguousarray(c[:, 1]))
    np.testing.assert_array_equal(r, heal.law.rate(fresh, st.thickness, st.concentration, st.snow))
    assert np.all(r > 0)


def test_first_non_finite_finds_the_first_bad_value_and_passes_huge_finite_ones():
    # the check sums each field first (a NaN or inf makes the sum non-finite); finite values
    # whose sum overflows must still pass, and a bad value is named with its index
    from lagice.fields import first_non_finite

    st = state()
    assert first_non_finite(st) is None
    st.thickness[:] = 1e308  # finite, but the sum overflows to inf
    assert first_non_finite(st) is None
    st.thickness[:] = 1.0
    st.damage[7] = np.inf
    st.damage[9] = np.nan
    spec, idx, val = first_non_finite(st)
    assert spec.name == "damage" and idx == 7 and val == np.inf
    assert first_non_finite(st, skip=("damage",)) is None
