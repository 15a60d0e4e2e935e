"""Synthetic forcing generators (forcing/synthetic.py): schedules, structure, determinism."""
import numpy as np
import pytest

from forcing import (
    Cyclone,
    RegularGrid,
    cyclone_wind,
    eddy_current,
    gyre_current,
    ocean_at_rest,
    random_cyclones,
    random_wind,
    record_times,
    uniform_current,
    uniform_wind,
)
from lagice.errors import ConfigError

H = 3600.0
DAY = 86400.0
BBOX = (0.0, 1.0e6, 0.0, 8.0e5)


@pytest.fixture(scope="module")
def grid():
    return RegularGrid.from_bbox(*BBOX, spacing_m=25e3)


def test_record_times():
    t = record_times(1.0 * DAY)
    np.testing.assert_array_equal(t, np.arange(5) * 6 * H)
    assert record_times(1.0 * DAY + 1)[-1] == 30 * H


def test_uniform_wind_ramp_and_turn(grid):
    w = uniform_wind(grid, 2 * DAY, speed_m_s=10.0, direction_deg=0.0)
    x = np.array([1e5, 5e5])
    y = np.array([2e5, 7e5])
    assert np.allclose(w.evaluate(0.0, x, y), 0.0)
    np.testing.assert_allclose(w.evaluate(3 * H, x, y)[:, 0], [5.0, 0.0], atol=1e-12)  # half ramp
    np.testing.assert_allclose(w.evaluate(6 * H, x, y)[:, 0], [10.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(w.evaluate(30 * H, x, y)[:, 1], [0.0, 10.0], atol=1e-12)  # turned 90°


def test_random_wind_deterministic(grid):
    a = random_wind(grid, 3 * DAY, seed=42).source.data
    b = random_wind(grid, 3 * DAY, seed=42).source.data
    c = random_wind(grid, 3 * DAY, seed=43).source.data
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    # uniform in space, changes every record
    assert np.all(a[:, :, :, :] == a[:, :, :1, :1])
    assert np.all(np.abs(np.diff(a[:, 0, 0, 0])) > 0)


def test_cyclone_structure():
    c = Cyclone(x0_m=0.0, y0_m=0.0, radius_m=200e3, max_speed_m_s=20.0, inflow_angle_deg=20.0,
                t_start_s=0.0, lifetime_s=2 * DAY)
    r = np.linspace(1e3, 1.5e6, 3001)
    u, v = c.wind(DAY, r, 0.0 * r)  # mid-life: full strength, points on +x axis
    speed = np.hypot(u, v)
    assert r[np.argmax(speed)] == pytest.approx(200e3, rel=1e-2)
    assert speed.max() == pytest.approx(20.0, rel=1e-4)
    assert np.all(v > 0)  # counter-clockwise: on +x axis the wind points to +y
    assert np.all(u < 0)  # inflow: towards the centre
    np.testing.assert_allclose(np.degrees(np.arctan2(-u, v)), 20.0, atol=1e-9)
    assert np.allclose(c.wind(-1.0, r, 0 * r), 0.0) and np.allclose(c.wind(2 * DAY + 1, r, 0 * r), 0.0)
    anti = Cyclone(x0_m=0.0, y0_m=0.0, anticyclone=True, lifetime_s=2 * DAY)
    ua, va = anti.wind(DAY, r, 0 * r)
    assert np.all(va < 0) and np.all(ua > 0)  # clockwise, outflow
    moving = Cyclone(x0_m=0.0, y0_m=0.0, velocity_m_s=(5.0, -2.0))
    assert moving.centre(DAY) == pytest.approx((5.0 * DAY, -2.0 * DAY))


def test_cyclone_wind_several_and_deterministic(grid):
    cs = random_cyclones(BBOX, 3 * DAY, 4, seed=7)
    assert cs == random_cyclones(BBOX, 3 * DAY, 4, seed=7)
    assert cs != random_cyclones(BBOX, 3 * DAY, 4, seed=8)
    w = cyclone_wind(grid, 3 * DAY, cs, background_m_s=(1.0, 0.0))
    w2 = cyclone_wind(grid, 3 * DAY, random_cyclones(BBOX, 3 * DAY, 4, seed=7), background_m_s=(1.0, 0.0))
    np.testing.assert_array_equal(w.source.data, w2.source.data)
    # superposition: sum of single-system fields
    single = sum(cyclone_wind(grid, 3 * DAY, [c]).source.data for c in cs)
    np.testing.assert_allclose(w.source.data[:, 0] - 1.0, single[:, 0], atol=1e-12)
    x = np.linspace(1e5, 9e5, 50)
    y = np.linspace(1e5, 7e5, 50)
    w.prepare(0.0, 3 * DAY, x, y)
    assert np.all(np.isfinite(w.evaluate(1.7 * DAY, x, y)))


def test_ocean_currents(grid):
    x = np.linspace(1e5, 9e5, 30)
    y = np.linspace(1e5, 7e5, 30)
    assert np.all(ocean_at_rest().evaluate(0.0, x, y) == 0.0)
    u = uniform_current(grid, 0.05, -0.02)
    u.prepare(0.0, 100 * DAY, x, y)  # steady: valid at all times
    np.testing.assert_allclose(u.evaluate(50 * DAY, x, y), np.array([[0.05], [-0.02]]) * np.ones(30))
    g = gyre_current(grid, 0.1, bbox=BBOX)
    d = g.source.data[0]
    dx = grid.x_m[1] - grid.x_m[0]
    dy = grid.y_m[1] - grid.y_m[0]
    assert np.hypot(d[0], d[1]).max() == pytest.approx(0.1, rel=2e-2)
    div = np.gradient(d[0], dx, axis=1) + np.gradient(d[1], dy, axis=0)
    inner = (slice(4, -4), slice(4, -4))
    vort = np.gradient(d[1], dx, axis=1) - np.gradient(d[0], dy, axis=0)
    # non-divergent to discretisation error, and rotating (clockwise: negative vorticity)
    assert np.abs(div[inner]).max() < 1e-2 * np.abs(vort[inner]).max()
    assert vort[inner].max() < 0
    # clockwise: eastward flow in the north of the box, westward in the south
    cx = 5e5
    top = g.evaluate(0.0, np.array([cx]), np.array([7e5]))
    bottom = g.evaluate(0.0, np.array([cx]), np.array([1e5]))
    assert top[0, 0] > 0 > bottom[0, 0]


def test_eddy_current():
    """Eddies of both senses: non-divergent (analytic ψ-derivatives: the grid divergence is
    discretisation error only), the largest speed as asked, vorticity of both signs at the
    eddy scale, one eddy per (4R)² of area, deterministic from the seed; an unresolved
    radius is refused."""
    g10 = RegularGrid.from_bbox(*BBOX, spacing_m=5e3)
    f = eddy_current(g10, 0.05, 30e3, seed=3)
    d = f.source.data[0]
    # one isolated eddy: its largest speed is the asked one, at r = R
    one = eddy_current(g10, 0.05, 30e3, spacing_radii=100.0, seed=3)
    assert "1 eddies" in one.source.name
    speed = np.hypot(*one.source.data[0])
    assert speed.max() == pytest.approx(0.05, rel=1e-2)
    X, Y = g10.mesh()
    k = np.unravel_index(np.argmax(speed), speed.shape)
    u1, v1 = one.source.data[0]
    dxy = g10.x_m[1] - g10.x_m[0]
    vort1 = np.gradient(v1, dxy, axis=1) - np.gradient(u1, dxy, axis=0)
    centre = np.unravel_index(np.argmax(np.abs(vort1)), speed.shape)  # |ζ| = |∇²ψ| peaks at the centre
    assert np.hypot(X[k] - X[centre], Y[k] - Y[centre]) == pytest.approx(30e3, abs=5e3)
    # the field: overlapping eddies can be faster, but not by much more than a few eddies'
    assert 0.05 * 0.9 < np.hypot(d[0], d[1]).max() < 0.05 * 3
    dx = g10.x_m[1] - g10.x_m[0]
    dy = g10.y_m[1] - g10.y_m[0]
    div = np.gradient(d[0], dx, axis=1) + np.gradient(d[1], dy, axis=0)
    vort = np.gradient(d[1], dx, axis=1) - np.gradient(d[0], dy, axis=0)
    inner = (slice(2, -2), slice(2, -2))
    assert np.abs(div[inner]).max() < 0.05 * np.abs(vort[inner]).max()
    # both senses, at comparable strength: an eddy field, not a gyre
    assert vort.max() > 0.3 * -vort.min() > 0 and -vort.min() > 0.3 * vort.max()
    n_expected = round((g10.x_m[-1] - g10.x_m[0]) * (g10.y_m[-1] - g10.y_m[0]) / (4 * 30e3) ** 2)
    assert f"{n_expected} eddies" in f.source.name
    np.testing.assert_array_equal(eddy_current(g10, 0.05, 30e3, seed=3).source.data, f.source.data)
    assert not np.array_equal(eddy_current(g10, 0.05, 30e3, seed=4).source.data, f.source.data)
    with pytest.raises(ConfigError, match="fewer than three forcing grid spacings"):
        eddy_current(g10, 0.05, 10e3)
    # in a scene the same rule is checked against forcing.grid_spacing_m before any mesh work
    from lagice.scenes.builder import validate_config
    from lagice.scenes.config import load_scene

    with pytest.raises(ConfigError, match=r"forcing\.ocean\.radius_m = 20000 m spans fewer than three"):
        validate_config(load_scene("winter_basin_pack", {"forcing.ocean": {"kind": "eddies", "radius_m": 20e3}}))
    validate_config(load_scene("winter_basin_pack", {"forcing.ocean": {"kind": "eddies", "radius_m": 30e3}}))


def test_bad_config(grid):
    with pytest.raises(ConfigError):
        uniform_wind(grid, DAY, speed_m_s=-1.0)
    with pytest.raises(ConfigError):
        Cyclone(x0_m=0, y0_m=0, radius_m=0.0)
    with pytest.raises(ConfigError):
        RegularGrid.from_bbox(0, 1, 0, 1, spacing_m=0.0)
