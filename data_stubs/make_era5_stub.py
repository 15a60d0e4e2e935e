"""Write ``data_stubs/era5_stub_arctic.nc``: a small ERA5-like forcing file.

Content (deterministic, no download): 4 days + 1 record, 6-hourly from
2020-01-01T00, on a coarse lon/lat grid over the Arctic (latitude 90→65°N
by 1.25°, descending as in ERA5; longitude −180..177.5° by 2.5°):

* ``u10``, ``v10`` [m s**-1]: eastward/northward 10 m wind of a cyclone
  crossing the Beaufort Sea plus an anticyclone over the central Arctic
  (built in EPSG:3413 with :class:`forcing.synthetic.Cyclone`, then rotated
  to east/north, so reading it back exercises the vector rotation);
* ``t2m`` [K]: −25 °C at 80°N warming 1 K per degree of latitude
  southwards, a 3 K diurnal-like wave and a warm sector east of the cyclone.

Stored as int16 with scale_factor/add_offset/_FillValue like ERA5 netCDF
from the CDS (≈ 0.3 MB).  Run: ``python data_stubs/make_era5_stub.py``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from forcing.records import LonLatGrid  # noqa: E402
from forcing.synthetic import Cyclone  # noqa: E402

OUT = Path(__file__).with_name("era5_stub_arctic.nc")


def _pack(values):
    """int16 encoding with ERA5-style scale_factor/add_offset."""
    vmin, vmax = float(np.nanmin(values)), float(np.nanmax(values))
    scale = (vmax - vmin) / (2 * 32766 - 2) or 1.0
    offset = 0.5 * (vmax + vmin)
    return {"dtype": "int16", "scale_factor": scale, "add_offset": offset, "_FillValue": np.int16(-32767)}


def make(path=OUT):
    lat = np.arange(90.0, 65.0 - 1e-9, -1.25)  # descending, ERA5 order
    lon = np.arange(-180.0, 180.0 - 1e-9, 2.5)
    times = np.datetime64("2020-01-01T00:00", "ns") + np.arange(17) * np.timedelta64(6, "h")
    t_s = (times - times[0]) / np.timedelta64(1, "s")

    grid = LonLatGrid(lon, lat[::-1], crs="EPSG:3413")
    lon2, lat2 = np.meshgrid(lon, lat[::-1])
    x, y = grid._to_xy.transform(lon2, lat2)
    th = grid.rotation()
    systems = [
        Cyclone(x0_m=-1.5e6, y0_m=1.5e6, velocity_m_s=(6.0, -4.0), radius_m=400e3, max_speed_m_s=18.0,
                inflow_angle_deg=25.0, t_start_s=-1.0e5, lifetime_s=5.0e5),
        Cyclone(x0_m=0.0, y0_m=0.0, velocity_m_s=(1.0, 1.0), radius_m=800e3, max_speed_m_s=8.0,
                inflow_angle_deg=10.0, t_start_s=-2.0e5, lifetime_s=8.0e5, anticyclone=True),
    ]
    u10 = np.empty((t_s.size,) + lat2.shape)
    v10 = np.empty_like(u10)
    t2m = np.empty_like(u10)
    for k, t in enumerate(t_s):
        ux = np.zeros_like(x)
        uy = np.zeros_like(x)
        for c in systems:
            cu, cv = c.wind(t, x, y)
            ux += cu
            uy += cv
        # projected x/y → east/north (inverse of LonLatGrid.rotate_east_north)
        u10[k] = ux * np.cos(th) + uy * np.sin(th)
        v10[k] = -ux * np.sin(th) + uy * np.cos(th)
        cx, cy = systems[0].centre(t)
        warm = 6.0 * np.exp(-(((x - cx - 500e3) ** 2 + (y - cy) ** 2) / (600e3) ** 2))
        t2m[k] = 273.15 - 25.0 - (lat2 - 80.0) + 3.0 * np.sin(2 * np.pi * t / 86400.0) + warm
    # ERA5 order: latitude descending
    u10, v10, t2m = (a[:, ::-1, :] for a in (u10, v10, t2m))
    ds = xr.Dataset(
        {
            "u10": (("time", "latitude", "longitude"), u10,
                    {"units": "m s**-1", "long_name": "10 metre U wind component",
                     "standard_name": "eastward_wind"}),
            "v10": (("time", "latitude", "longitude"), v10,
                    {"units": "m s**-1", "long_name": "10 metre V wind component",
                     "standard_name": "northward_wind"}),
            "t2m": (("time", "latitude", "longitude"), t2m,
                    {"units": "K", "long_name": "2 metre temperature", "standard_name": "air_temperature"}),
        },
        coords={
            "time": ("time", times, {"long_name": "time"}),
            "latitude": ("latitude", lat, {"units": "degrees_north", "long_name": "latitude"}),
            "longitude": ("longitude", lon, {"units": "degrees_east", "long_name": "longitude"}),
        },
        attrs={"Conventions": "CF-1.6",
               "history": "synthetic ERA5-like stub made by data_stubs/make_era5_stub.py (lagice)"},
    )
    enc = {v: _pack(ds[v].values) for v in ("u10", "v10", "t2m")}
    enc["time"] = {"units": "hours since 1900-01-01 00:00:00.0", "calendar": "gregorian", "dtype": "int32"}
    ds.to_netcdf(path, encoding=enc, format="NETCDF4_CLASSIC")
    return path


if __name__ == "__main__":
    p = make()
    print(f"wrote {p} ({p.stat().st_size / 1e6:.2f} MB)")
