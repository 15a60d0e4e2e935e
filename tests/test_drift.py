"""Ice drift against the wind (lagice.diagnostics.drift): the complex wind factor of
Thorndike and Colony (1982), daily drifter velocities and winds along the tracks."""
import cmath
import math

import numpy as np
import pytest

from lagice.diagnostics.drift import (
    daily_drift,
    geostrophic_from_surface,
    track_mean,
    wind_factor,
)


def _random_winds(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.normal(0.0, 8.0, (n, 2)) + np.array([2.0, -1.0])


def _apply(a: complex, g, c=0j):
    z = a * (g[:, 0] + 1j * g[:, 1]) + c
    return np.column_stack([z.real, z.imag])


def test_wind_factor_recovers_a_known_response():
    g = _random_winds(400)
    a = 0.008 * cmath.exp(1j * math.radians(-5.0))  # Thorndike and Colony's winter response
    u = _apply(a, g, 0.01 - 0.02j)
    fit = wind_factor(u, g)
    assert fit.factor == pytest.approx(0.008, rel=1e-12)
    assert fit.angle_deg == pytest.approx(-5.0, abs=1e-9)
    assert fit.current_m_s == pytest.approx((0.01, -0.02), abs=1e-14)
    assert fit.r2 == pytest.approx(1.0, abs=1e-12)
    assert fit.n == 400
    # without the mean current the same data give a biased factor and R² < 1
    fit0 = wind_factor(u, g, with_current=False)
    assert fit0.current_m_s == (0.0, 0.0)
    assert fit0.r2 < 1.0 - 1e-3
    # data that have no current are fitted exactly either way
    u0 = _apply(a, g)
    assert wind_factor(u0, g, with_current=False).factor == pytest.approx(0.008, rel=1e-12)


def test_wind_factor_explained_variance_with_noise():
    """R² is the share of the ice-velocity variance the wind explains: with independent
    noise of variance σ² per component it tends to var(AG) / (var(AG) + 2σ²)."""
    g = _random_winds(20000, seed=1)
    a = 0.01 * cmath.exp(1j * 0.3)
    rng = np.random.default_rng(2)
    sigma = 0.04
    u = _apply(a, g) + rng.normal(0.0, sigma, g.shape)
    fit = wind_factor(u, g)
    var_signal = abs(a) ** 2 * 2 * 8.0 ** 2
    assert fit.r2 == pytest.approx(var_signal / (var_signal + 2 * sigma ** 2), abs=0.01)
    assert fit.factor == pytest.approx(0.01, rel=0.02)
    assert fit.angle_deg == pytest.approx(math.degrees(0.3), abs=1.5)


def test_wind_factor_skips_missing_pairs_and_refuses_too_few():
    g = _random_winds(50)
    u = _apply(0.005j, g)
    u[3] = np.nan
    g[7] = np.nan
    fit = wind_factor(u, g)
    assert fit.n == 48
    assert fit.factor == pytest.approx(0.005, rel=1e-12)
    assert fit.angle_deg == pytest.approx(90.0, abs=1e-9)
    with pytest.raises(ValueError, match="need at least 3"):
        wind_factor(u[2:5], g[2:5])  # pair 3 is missing: two left
    with pytest.raises(ValueError, match="does not vary"):
        wind_factor(u[:10], np.tile([1.0, 2.0], (10, 1)))
    with pytest.raises(ValueError, match="same shape"):
        wind_factor(u, g[:10])


def test_daily_drift_of_tracks_at_constant_velocity():
    t = np.arange(0.0, 3.5 * 86400.0 + 1.0, 600.0)
    v = np.array([[0.1, -0.05], [-0.02, 0.07], [0.3, 0.0]])
    x = 1e5 + v[:, :1] * t
    y = -2e5 + v[:, 1:] * t
    x[2, 144] = np.nan  # track 2 has no position at the end of day 1 (the start of day 2)
    x[0, 200] = np.nan  # a gap inside day 2 of track 0 does not change that day's displacement
    starts, vel, ok = daily_drift(t, x, y, lost=[False, True, False])
    assert np.allclose(starts, [0.0, 86400.0, 172800.0])
    assert ok.tolist() == [[True, True, True], [False, False, False], [False, False, True]]
    assert np.allclose(vel[ok], np.repeat(v, 3, axis=0).reshape(3, 3, 2)[ok], rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="increase strictly"):
        daily_drift(t[::-1], x, y)
    with pytest.raises(ValueError, match="lost"):
        daily_drift(t, x, y, lost=[False])


def test_track_mean_follows_the_track():
    """A wind linear in time and space, on tracks moving at constant velocity, is linear in
    time along each track: its daily mean is its value at mid-day."""
    t = np.arange(0.0, 2 * 86400.0 + 1.0, 600.0)
    x = np.array([0.0, 5e4])[:, None] + 0.2 * t
    y = np.array([1e4, -3e4])[:, None] - 0.1 * t

    def wind(tt, xx, yy):
        return 3.0 + 1e-5 * tt + 2e-5 * xx, -1.0 + 4e-5 * yy

    starts = np.array([0.0, 86400.0])
    m = track_mean(wind, t, x, y, starts)
    mid = starts + 43200.0
    for k in range(2):
        xm = x[k, 0] + 0.2 * mid
        ym = y[k, 0] - 0.1 * mid
        assert np.allclose(m[k, :, 0], 3.0 + 1e-5 * mid + 2e-5 * xm, rtol=0, atol=1e-12)
        assert np.allclose(m[k, :, 1], -1.0 + 4e-5 * ym, rtol=0, atol=1e-12)


def test_geostrophic_wind_of_the_climatology():
    """The climatology makes its 10-m wind from ∇p as s R(θ) k×∇p/(ρa f); the diagnostic's
    inverse must give back the geostrophic wind k×∇p/(ρa f), perpendicular to ∇p."""
    from forcing.climatology import RHO_AIR, ClimatologyParams, _rotate

    p = ClimatologyParams()
    grad = np.random.default_rng(3).normal(0.0, 1e-3, (20, 2))  # Pa m-1
    u10 = grad @ _rotate(p).T
    g = geostrophic_from_surface(u10, p.surface_factor, p.cross_isobar_angle_deg)
    expected = np.column_stack([-grad[:, 1], grad[:, 0]]) / (RHO_AIR * p.coriolis_s)
    assert np.allclose(g, expected, rtol=1e-12, atol=0.0)
    assert np.allclose(np.sum(g * grad, axis=1), 0.0, atol=1e-15)
    # the 10-m wind is turned towards low pressure: it has a component down the gradient
    assert np.all(np.sum(u10 * grad, axis=1) < 0)
    with pytest.raises(ValueError, match="surface_factor"):
        geostrophic_from_surface(u10, 0.0, 25.0)


@pytest.mark.slow
def test_cli_wind_factor_of_a_real_run(tmp_path):
    """``lagice diagnose RUN --wind-factor`` on a real run of the flagship scene (80 km, 2 days):
    the wind it rebuilds from the drifter file is the run's own wind, bit for bit, and the
    JSON holds the fit of the drifters' daily velocities on it."""
    import json
    import subprocess
    import sys

    import xarray as xr

    from lagice.diagnostics.drift import run_wind
    from lagice.forces import WindStress
    from lagice.scenes.builder import build_model
    from lagice.scenes.config import load_scene

    out = tmp_path / "run"
    sets = {"domain.resolution_m": 80e3, "run.duration": "2d"}
    cmd = [sys.executable, "-m", "lagice.cli", "run", "winter_basin_pack", "--out", str(out), "--set",
           "output.plot=false", "--set", "run.progress=false"]
    cmd += [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    d = subprocess.run([sys.executable, "-m", "lagice.cli", "diagnose", str(out), "--wind-factor"],
                       capture_output=True, text=True, timeout=600)
    assert d.returncode == 0, d.stderr
    assert "wind factor |A|" in d.stdout and "Thorndike and Colony" in d.stdout
    res = json.loads((out / "diagnostics" / "drift_response.json").read_text())
    with xr.open_dataset(out / "drifters.nc") as ds:
        cfg = json.loads(ds.attrs["lagice_config"])
        n_tracks, lost = ds.sizes["trajectory"], int(ds["lost"].values.sum())
    assert res["wind"] == "geostrophic" and res["days"] == 2
    assert res["fit"]["n"] == 2 * (n_tracks - lost) == len(res["daily_speeds_g_u_m_s"])
    assert 0.0 < res["fit"]["factor"] < 0.1 and -1.0 <= res["fit"]["r2"] <= 1.0
    lo, hi = res["factor_5_95_over_drifters"]
    assert lo <= hi
    # the rebuilt wind is the wind the run's model had (the same scene_wind on the same mesh)
    model = build_model(load_scene("winter_basin_pack", sets))
    run_field = next(f.wind for f in model.forces if isinstance(f, WindStress))
    field, (kind, s, th) = run_wind(cfg)
    assert (kind, s, th) == ("geostrophic", 0.7, 25.0)
    xy = model.mesh.nodes[::7]
    for t in (0.0, 3600.0 * 13.5, 2 * 86400.0):
        a, b = run_field(t, xy[:, 0], xy[:, 1]), field(t, xy[:, 0], xy[:, 1])
        assert np.array_equal(np.asarray(a[0]), np.asarray(b[0])) and np.array_equal(np.asarray(a[1]), np.asarray(b[1]))
