"""Synthetic air temperature (thermo/air_temperature.py)."""
import numpy as np
import pytest

from forcing import Forcing, RegularGrid
from thermo import synthetic_air_temperature

DAY = 86400.0


@pytest.fixture(scope="module")
def grid():
    return RegularGrid.from_bbox(0.0, 1e6, 0.0, 1e6, spacing_m=100e3)


def test_deterministic_from_seed(grid):
    a = synthetic_air_temperature(grid, 365 * DAY, seed=1).source.data
    b = synthetic_air_temperature(grid, 365 * DAY, seed=1).source.data
    c = synthetic_air_temperature(grid, 365 * DAY, seed=2).source.data
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_seasonal_cycle_and_synoptic_variability(grid):
    f = synthetic_air_temperature(grid, 365 * DAY, seed=3)
    times = f.source.times_s
    assert np.all(np.diff(times) == 6 * 3600.0)
    series = f.source.data[:, 0, 0, 0]
    day = 1 + times / DAY
    winter = series[(day > 30) & (day < 60)].mean()
    summer = series[(day > 200) & (day < 230)].mean()
    assert winter < -20.0 and summer > -5.0 and series.max() > 0.0  # melt season exists
    anomaly = series + 14.0 + 15.0 * np.cos(2 * np.pi * (day - 45) / 365.25)
    assert 2.5 < anomaly.std() < 6.0
    lag1 = np.corrcoef(anomaly[:-1], anomaly[1:])[0, 1]
    assert lag1 == pytest.approx(np.exp(-0.25 / 3.0), abs=0.08)


def test_uniform_or_weak_gradient_through_forcing(grid):
    x = np.array([1e5, 9e5])
    y = np.array([5e5, 5e5])
    flat = Forcing(air_temperature=synthetic_air_temperature(grid, 10 * DAY, seed=0))
    flat.prepare(0.0, 10 * DAY, x, y)
    v = flat.evaluate(3.3 * DAY, x, y).air_temperature
    assert v[0] == pytest.approx(v[1], abs=1e-12)
    grad = synthetic_air_temperature(grid, 10 * DAY, seed=0, gradient_k_per_1000km=(2.0, 0.0))
    g = grad.evaluate(3.3 * DAY, x, y)
    assert g[1] - g[0] == pytest.approx(2.0 * 0.8, rel=1e-9)
    assert 0.5 * (g[0] + g[1]) == pytest.approx(v[0], abs=1e-9)
