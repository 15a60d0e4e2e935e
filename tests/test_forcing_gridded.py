"""Gridded netCDF forcing: lon/lat vs projected grids, vector rotation, bad input."""
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from pyproj import Transformer

from forcing import open_air_temperature, open_gridded, open_wind
from lagice.errors import ForcingError

ROOT = Path(__file__).resolve().parents[1]
TO_XY = Transformer.from_crs("EPSG:4326", "EPSG:3413", always_xy=True)
TIMES = np.datetime64("2021-02-01T00:00", "ns") + np.arange(5) * np.timedelta64(6, "h")
DAY = 86400.0


def temp_c(x, y, t):
    """Smooth air temperature [°C] defined in the projected plane."""
    return -20.0 + 3.0 * np.sin(x / 1.0e6) + 2.0 * np.cos(y / 8.0e5) + 2.0 * t / DAY


def wind_xy(x, y, t):
    """Smooth wind [m s-1] in projected x/y components."""
    return 5.0 + 2.0 * np.sin(y / 1.2e6) + t / DAY, -3.0 + 1.5 * np.cos(x / 9.0e5)


def write_lonlat(path, lon, lat, fields, times=TIMES, time_attrs=True, lat_descending=True):
    """ERA5-like file: fields = {name: (array (nt, nlat, nlon), attrs)}."""
    if lat_descending:
        lat = lat[::-1]
        fields = {k: (v[:, ::-1], a) for k, (v, a) in fields.items()}
    ds = xr.Dataset({k: (("time", "latitude", "longitude"), v, a) for k, (v, a) in fields.items()},
                    coords={"time": times, "latitude": ("latitude", lat, {"units": "degrees_north"}),
                            "longitude": ("longitude", lon, {"units": "degrees_east"})})
    enc = {"time": {"units": "hours since 1900-01-01"}} if time_attrs else {}
    ds.to_netcdf(path, encoding=enc)
    return path


def lonlat_fields(lon, lat, times_s):
    """Temperature in K and east/north wind from the x/y definitions.

    The rotation uses the analytic EPSG:3413 angle θ = lon + 45° (independent
    of the pyproj step used by the reader): east = (cos θ, sin θ), north = (−sin θ, cos θ).
    """
    LON, LAT = np.meshgrid(lon, lat)
    X, Y = TO_XY.transform(LON, LAT)
    th = np.deg2rad(LON + 45.0)
    T, U, V = [], [], []
    for t in times_s:
        ux, uy = wind_xy(X, Y, t)
        T.append(temp_c(X, Y, t) + 273.15)
        U.append(ux * np.cos(th) + uy * np.sin(th))
        V.append(-ux * np.sin(th) + uy * np.cos(th))
    return np.array(T), np.array(U), np.array(V)


def era5_like(path, **kw):
    lon = np.arange(-180.0, 180.0, 1.0)
    lat = np.arange(65.0, 90.01, 0.5)
    T, U, V = lonlat_fields(lon, lat, (TIMES - TIMES[0]) / np.timedelta64(1, "s"))
    fields = {"t2m": (T, {"units": "K"}), "u10": (U, {"units": "m s**-1"}), "v10": (V, {"units": "m s**-1"})}
    fields.update(kw.pop("extra", {}))
    for name, attrs in kw.pop("attrs", {}).items():
        fields[name] = (fields[name][0], attrs)
    return write_lonlat(path, lon, lat, fields, **kw)


def nodes(n=400, half=1.5e6, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-half, half, n), rng.uniform(-half, half, n)


def test_lonlat_and_projected_files_agree(tmp_path):
    ll = era5_like(tmp_path / "ll.nc")
    # the same fields on a 25 km projected grid
    gx = np.arange(-2.0e6, 2.0e6 + 1, 25e3)
    gy = np.arange(-2.0e6, 2.0e6 + 1, 25e3)
    X, Y = np.meshgrid(gx, gy)
    ts = (TIMES - TIMES[0]) / np.timedelta64(1, "s")
    T = np.array([temp_c(X, Y, t) for t in ts])
    W = [wind_xy(X, Y, t) for t in ts]
    xy = tmp_path / "xy.nc"
    xr.Dataset({"t2m": (("time", "y", "x"), T, {"units": "degC"}),
                "u10": (("time", "y", "x"), np.array([w[0] for w in W]), {"units": "m/s"}),
                "v10": (("time", "y", "x"), np.array([w[1] for w in W]), {"units": "m/s"})},
               coords={"time": TIMES, "x": ("x", gx / 1e3, {"units": "km"}),
                       "y": ("y", gy, {"units": "m"})}).to_netcdf(xy)

    x, y = nodes()
    t = 0.37 * DAY
    t_ll, t_xy = open_air_temperature(ll), open_air_temperature(xy)
    w_ll, w_xy = open_wind(ll), open_wind(xy)
    for f in (t_ll, t_xy, w_ll, w_xy):
        f.prepare(0.0, DAY, x, y)
    a, b = t_ll.evaluate(t, x, y), t_xy.evaluate(t, x, y)
    exact = temp_c(x, y, t)
    assert np.max(np.abs(b - exact)) < 1e-3  # fine projected grid
    assert np.max(np.abs(a - exact)) < 5e-3  # 1° × 0.5° lon/lat grid
    assert np.max(np.abs(a - b)) < 5e-3
    wa, wb = w_ll.evaluate(t, x, y), w_xy.evaluate(t, x, y)
    ux, uy = wind_xy(x, y, t)
    assert np.max(np.abs(wb[0] - ux)) < 1e-3 and np.max(np.abs(wb[1] - uy)) < 1e-3
    # rotated east/north → x/y within interpolation error
    assert np.max(np.abs(wa[0] - ux)) < 5e-3 and np.max(np.abs(wa[1] - uy)) < 5e-3
    # moving the mesh: values follow the nodes
    x2, y2 = x + 3e4, y - 2e4
    np.testing.assert_allclose(t_ll.evaluate(t, x2, y2, mesh_version=2), temp_c(x2, y2, t), atol=2e-2)


@pytest.mark.parametrize("lon, expected", [(-45.0, (0.0, 1.0)), (45.0, (-1.0, 0.0)),
                                           (135.0, (0.0, -1.0)), (-135.0, (1.0, 0.0))])
def test_northward_wind_rotation(tmp_path, lon, expected):
    """EPSG:3413 (central meridian −45°): north is +y at lon −45°, −x at lon 45°."""
    lons = np.arange(-180.0, 180.0, 5.0)
    lat = np.arange(60.0, 90.01, 2.5)
    shape = (TIMES.size, lat.size, lons.size)
    path = write_lonlat(tmp_path / "north.nc", lons, lat, {
        "u10": (np.zeros(shape), {"units": "m s-1"}), "v10": (np.full(shape, 10.0), {"units": "m s-1"})})
    w = open_wind(path)
    x, y = TO_XY.transform(np.array([lon]), np.array([75.0]))
    val = w.evaluate(0.5 * DAY, np.asarray(x), np.asarray(y))
    np.testing.assert_allclose(val[:, 0], 10.0 * np.array(expected), atol=1e-6)
    # an eastward wind at lon −45° points to +x
    path2 = write_lonlat(tmp_path / "east.nc", lons, lat, {
        "u10": (np.full(shape, 10.0), {"units": "m s-1"}), "v10": (np.zeros(shape), {"units": "m s-1"})})
    xe, ye = TO_XY.transform(np.array([-45.0]), np.array([75.0]))
    np.testing.assert_allclose(open_wind(path2).evaluate(0.0, xe, ye)[:, 0], [10.0, 0.0], atol=1e-6)


def test_era5_stub_reads():
    path = ROOT / "data_stubs" / "era5_stub_arctic.nc"
    assert path.stat().st_size < 1_000_000
    x, y = nodes(2000, half=1.6e6)
    w, t = open_wind(path), open_air_temperature(path)
    w.prepare(0.0, 4 * DAY, x, y)
    t.prepare(0.0, 4 * DAY, x, y)
    v = w.evaluate(1.3 * DAY, x, y)
    ta = t.evaluate(1.3 * DAY, x, y)
    assert np.all(np.isfinite(v)) and np.max(np.hypot(*v)) < 40.0
    assert -45.0 < ta.min() < ta.max() < 0.0


# ----------------------------------------------------------------------------
# bad input: ForcingError naming file, variable and problem
# ----------------------------------------------------------------------------
def _assert_names(exc, path, var):
    msg = str(exc.value)
    assert str(path) in msg, msg
    assert var in msg, msg


def test_missing_variable(tmp_path):
    p = era5_like(tmp_path / "f.nc")
    with pytest.raises(ForcingError, match="missing variable") as e:
        open_wind(p, u="u10", v="v_missing")
    _assert_names(e, p, "v_missing")


@pytest.mark.parametrize("attrs, problem", [({}, "missing units"), ({"units": "furlongs"}, "wrong units")])
def test_missing_or_wrong_units(tmp_path, attrs, problem):
    p = era5_like(tmp_path / "f.nc", attrs={"t2m": attrs})
    with pytest.raises(ForcingError, match=problem) as e:
        open_air_temperature(p)
    _assert_names(e, p, "t2m")


def test_implausible_values_wrong_units(tmp_path):
    p = era5_like(tmp_path / "f.nc", attrs={"t2m": {"units": "degC"}})  # values are in K
    f = open_air_temperature(p)
    x, y = nodes()
    with pytest.raises(ForcingError, match="implausible") as e:
        f.prepare(0.0, DAY, x, y)
    _assert_names(e, p, "t2m")


@pytest.mark.parametrize("fill", [np.nan, 9.96921e36])
def test_nan_or_fill_inside_domain(tmp_path, fill):
    lon = np.arange(-180.0, 180.0, 2.0)
    lat = np.arange(60.0, 90.01, 1.0)
    T = np.full((TIMES.size, lat.size, lon.size), 250.0)
    T[2, 20, 60] = fill  # lat 80, lon −60: inside a 1500 km box around the pole
    p = write_lonlat(tmp_path / "f.nc", lon, lat, {"t2m": (T, {"units": "K"})})
    f = open_air_temperature(p)
    x, y = nodes()
    with pytest.raises(ForcingError, match="NaN or fill") as e:
        f.prepare(0.0, DAY, x, y)
    _assert_names(e, p, "t2m")
    # the same hole outside the run window or away from the mesh is fine
    open_air_temperature(p).prepare(0.0, 0.2 * DAY, x, y)
    T2 = np.full_like(T, 250.0)
    T2[:, 1, :] = np.nan  # lat 61: outside the mesh box
    p2 = write_lonlat(tmp_path / "g.nc", lon, lat, {"t2m": (T2, {"units": "K"})})
    open_air_temperature(p2).prepare(0.0, DAY, x, y)
    # met at run time (mesh drifted onto the hole) → ForcingError too
    g = open_air_temperature(p, time_extrapolation="error")
    xh, yh = TO_XY.transform(np.array([-60.0]), np.array([80.0]))
    with pytest.raises(ForcingError, match="NaN or fill") as e:
        g.evaluate(12 * 3600.0, np.asarray(xh), np.asarray(yh))
    _assert_names(e, p, "t2m")


def test_time_not_monotonic(tmp_path):
    times = TIMES.copy()
    times[3] = times[1]
    p = era5_like(tmp_path / "f.nc", times=times)
    with pytest.raises(ForcingError, match="not monotonic") as e:
        open_wind(p)
    _assert_names(e, p, "time")


def test_time_with_a_gap_is_refused(tmp_path):
    """A 6-hourly file that lacks two records (an 18 h gap): refused, naming the file, the
    records either side of the gap and the expected spacing; an even file opens."""
    times = np.datetime64("2021-02-01T00:00", "ns") + np.array([0, 1, 4, 5, 6]) * np.timedelta64(6, "h")
    p = era5_like(tmp_path / "gap.nc", times=times)
    with pytest.raises(ForcingError, match="not evenly spaced") as e:
        open_wind(p)
    _assert_names(e, p, "time")
    msg = str(e.value)
    assert "between record 1 (2021-02-01T06:00:00) and record 2 (2021-02-02T00:00:00), 18 h apart" in msg
    assert "the records are 6 h apart" in msg
    assert open_wind(era5_like(tmp_path / "even.nc")).source.record_times.size == 5


def test_time_not_cf(tmp_path):
    lon = np.arange(0.0, 360.0, 10.0)
    lat = np.arange(70.0, 85.01, 5.0)
    ds = xr.Dataset({"t2m": (("time", "latitude", "longitude"), np.full((3, lat.size, lon.size), 250.0),
                             {"units": "K"})},
                    coords={"time": ("time", np.arange(3.0)), "latitude": lat, "longitude": lon})
    p = tmp_path / "f.nc"
    ds.to_netcdf(p)
    with pytest.raises(ForcingError, match="CF time") as e:
        open_air_temperature(p)
    _assert_names(e, p, "time")


def test_run_outside_records(tmp_path):
    p = era5_like(tmp_path / "f.nc")
    x, y = nodes()
    f = open_wind(p)
    with pytest.raises(ForcingError, match="outside the records") as e:
        f.prepare(0.0, 3 * DAY, x, y)
    _assert_names(e, p, "u10")
    g = open_wind(p, reference_time="2021-01-31T00:00")  # file starts 1 day after model t = 0
    with pytest.raises(ForcingError, match="outside the records"):
        g.prepare(0.0, 0.5 * DAY, x, y)
    open_wind(p, time_extrapolation="hold").prepare(0.0, 3 * DAY, x, y)  # opt-in


def test_mesh_outside_grid(tmp_path):
    lon = np.arange(-180.0, 180.0, 5.0)
    lat = np.arange(80.0, 90.01, 2.5)  # north of 80°N only
    shape = (TIMES.size, lat.size, lon.size)
    p = write_lonlat(tmp_path / "f.nc", lon, lat, {"t2m": (np.full(shape, 250.0), {"units": "K"})})
    x, y = nodes(half=2.0e6)
    with pytest.raises(ForcingError, match="outside the forcing grid") as e:
        open_air_temperature(p).prepare(0.0, DAY, x, y)
    _assert_names(e, p, "t2m")
    f = open_air_temperature(p, space_extrapolation="clamp")  # opt-in: edge values
    f.prepare(0.0, DAY, x, y)
    assert np.allclose(f.evaluate(0.0, x, y), 250.0 - 273.15)


def test_sector_grid_and_0_360_longitudes(tmp_path):
    """A 0..359 longitude file and a sector file give the same values."""
    lon = np.arange(0.0, 360.0, 1.0)
    lat = np.arange(65.0, 90.01, 0.5)
    T, U, V = lonlat_fields(lon, lat, (TIMES - TIMES[0]) / np.timedelta64(1, "s"))
    p = write_lonlat(tmp_path / "f.nc", lon, lat, {"t2m": (T, {"units": "K"})}, lat_descending=False)
    sec = (lon >= 180.0) & (lon <= 300.0)  # 180°E..60°W sector
    p2 = write_lonlat(tmp_path / "s.nc", lon[sec] - 360.0, lat, {"t2m": (T[:, :, sec], {"units": "K"})})
    lo = np.array([-170.0, -120.0, -70.0])
    x, y = TO_XY.transform(lo, np.array([70.0, 80.0, 75.0]))
    a = open_air_temperature(p).evaluate(DAY / 3, x, y)
    b = open_air_temperature(p2).evaluate(DAY / 3, x, y)
    np.testing.assert_allclose(a, b, atol=1e-9)
    np.testing.assert_allclose(a, temp_c(np.asarray(x), np.asarray(y), DAY / 3), atol=2e-2)


def test_open_gridded_vector_frame_xy(tmp_path):
    p = era5_like(tmp_path / "f.nc")
    f = open_gridded(p, ("u10", "v10"), quantity="wind", vector_frame="xy")
    assert f.source.vector_frame == "xy"


def test_longitudes_0_to_360_inclusive(tmp_path):
    """A duplicated 360° column (0..360) is dropped, values unchanged."""
    lon = np.arange(0.0, 360.01, 2.0)
    lat = np.arange(65.0, 90.01, 1.0)
    T, _, _ = lonlat_fields(lon, lat, (TIMES - TIMES[0]) / np.timedelta64(1, "s"))
    p = write_lonlat(tmp_path / "f.nc", lon, lat, {"t2m": (T, {"units": "K"})})
    f = open_air_temperature(p)
    assert f.grid.periodic_x and f.grid.shape == (lat.size, lon.size - 1)
    x, y = TO_XY.transform(np.array([-1.0, 1.0, 179.0]), np.array([75.0, 75.0, 80.0]))
    np.testing.assert_allclose(f.evaluate(0.0, x, y), temp_c(np.asarray(x), np.asarray(y), 0.0), atol=3e-2)
