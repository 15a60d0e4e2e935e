"""Healing laws (thermo/healing.py)."""
import numpy as np
import pytest

from lagice.errors import ConfigError
from thermo import ConstantHealing, FreezingDegreeDayHealing, ThermodynamicHealing, make_healing

DAY = 86400.0


def test_no_healing_above_freezing():
    h = ThermodynamicHealing()
    ta = np.array([-1.8, -1.0, 0.0, 5.0])
    assert np.all(h.rate(ta) == 0.0)
    d = np.full(4, 0.7)
    assert np.all(h.apply(d, ta, DAY) == 0.0) and np.all(d == 0.7)
    f = FreezingDegreeDayHealing()
    assert np.all(f.rate(ta, d) == 0.0)
    f.apply(d, ta, DAY)
    assert np.all(d == 0.7)


def test_colder_heals_faster_by_the_law_ratio():
    h = ThermodynamicHealing(th0_s=20 * DAY, delta_t0_k=20.0, freezing_point_c=-1.8)
    r30, r10 = h.rate(np.array([-30.0, -10.0]))
    assert r30 / r10 == pytest.approx((30.0 - 1.8) / (10.0 - 1.8), rel=1e-14)
    # at ΔT = ΔT0 the healing time is th0
    assert h.rate(-21.8) == pytest.approx(1.0 / (20 * DAY))
    f = FreezingDegreeDayHealing()
    d = np.array([0.5, 0.5])
    f30, f10 = f.rate(np.array([-30.0, -10.0]), d)
    assert f30 / f10 == pytest.approx(28.2 / 8.2, rel=1e-14)


def test_apply_floors_at_zero_and_returns_decrease():
    h = ConstantHealing(healing_time_s=1e5)
    d = np.array([0.0, 0.3, 1.0])
    dec = h.apply(d, np.full(3, -20.0), 5e4)
    np.testing.assert_allclose(d, [0.0, 0.0, 0.5])
    np.testing.assert_allclose(dec, [0.0, 0.3, 0.5])
    assert h.rate(damage=d).shape == (3,)


def test_fdd_healing_follows_sqrt_of_freezing_degree_days():
    """Girard 2010 eq. 5.8: d_seed = 1 − d grows like √(t (Tf − Ta)); eq. 5.11 is its Euler step."""
    beta = 1e3 * DAY
    f = FreezingDegreeDayHealing(beta_s_k=beta)
    ta = -21.8
    d_one = np.array([1.0])  # fully damaged: finite exact step
    f.apply(d_one, ta, 10 * DAY)
    d_many = np.array([1.0])
    for _ in range(1000):
        f.apply(d_many, ta, 0.01 * DAY)
    expected = 1.0 - np.sqrt(2 * 10 * DAY * 20.0 / beta)
    assert d_one[0] == pytest.approx(expected, rel=1e-12)
    assert d_many[0] == pytest.approx(expected, rel=1e-12)
    # explicit eq. 5.11 converges to the same
    ds = 1.0 - 0.5
    d_exact = np.array([0.5])
    f.apply(d_exact, ta, DAY)
    for _ in range(10000):
        ds += (0.0001 * DAY) / (beta / 20.0 * ds)
    assert 1.0 - ds == pytest.approx(d_exact[0], rel=1e-5)


def test_make_healing():
    assert make_healing(None) is None and make_healing("none") is None
    assert isinstance(make_healing("constant", healing_time_s=3e4), ConstantHealing)
    assert isinstance(make_healing("fdd"), FreezingDegreeDayHealing)
    with pytest.raises(ConfigError):
        make_healing("magic")
    with pytest.raises(ConfigError):
        make_healing("thermodynamic", th0_s=-1.0)
    with pytest.raises(ConfigError):
        FreezingDegreeDayHealing().rate(-20.0)
