"""Gridded forcing files: netCDF with a CF time axis (docs/design.md §6).

A file holds records on either

* a **lon/lat grid** (coordinates ``longitude``/``latitude`` or ``lon``/``lat``,
  ERA5 style, latitudes in either order): positions are mapped to lon/lat
  with pyproj from the model's projected CRS (default EPSG:3413) and vector
  components given east/north are rotated into the projected x/y frame
  (:meth:`forcing.records.LonLatGrid.rotation`); or
* a **projected x/y grid** (coordinates ``x``/``y`` in m or km, in the
  model's CRS): vector components are already x/y.

Data are read lazily with xarray, one record at a time, when
:class:`forcing.records.RecordField` needs it.  Values are converted to
model units on read: velocities to m s-1, temperatures to °C.

Everything wrong with a file raises :class:`lagice.errors.ForcingError`
naming the file, the variable and the problem: missing variable, missing or
unknown units, implausible values (typically wrong units), time coordinate
missing/not CF/not strictly increasing; and, from
:meth:`RecordField.prepare`, run times outside the records, mesh outside
the grid, NaN or fill values over the mesh.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from lagice.errors import ConfigError, ForcingError

from .records import LonLatGrid, RecordField, RegularGrid

#: accepted units → (scale, offset) to model units (value*scale + offset)
VELOCITY_UNITS = {
    "m s-1": (1.0, 0.0), "m s**-1": (1.0, 0.0), "m/s": (1.0, 0.0), "m s^-1": (1.0, 0.0),
    "m.s-1": (1.0, 0.0), "ms-1": (1.0, 0.0), "meter second-1": (1.0, 0.0),
    "meters per second": (1.0, 0.0), "metre second-1": (1.0, 0.0),
    "cm s-1": (0.01, 0.0), "cm/s": (0.01, 0.0), "cm s**-1": (0.01, 0.0),
}
TEMPERATURE_UNITS = {
    "k": (1.0, -273.15), "kelvin": (1.0, -273.15), "degk": (1.0, -273.15),
    "degc": (1.0, 0.0), "°c": (1.0, 0.0), "c": (1.0, 0.0), "celsius": (1.0, 0.0),
    "degree_celsius": (1.0, 0.0), "degrees_celsius": (1.0, 0.0), "deg_c": (1.0, 0.0),
    "degrees_c": (1.0, 0.0), "degree_c": (1.0, 0.0),
}
LENGTH_UNITS = {"m": 1.0, "meter": 1.0, "metre": 1.0, "meters": 1.0, "metres": 1.0,
                "km": 1000.0, "kilometer": 1000.0, "kilometre": 1000.0, "kilometers": 1000.0,
                "kilometres": 1000.0}
#: quantity → (unit table, model units, plausible range in model units)
QUANTITIES = {
    "wind": (VELOCITY_UNITS, "m s-1", (-150.0, 150.0)),
    "current": (VELOCITY_UNITS, "m s-1", (-20.0, 20.0)),
    "temperature": (TEMPERATURE_UNITS, "degC", (-100.0, 60.0)),
}
FILL_THRESHOLD = 1.0e30  # |value| above this is an undeclared fill value

_TIME_NAMES = ("time", "valid_time", "t")
_LON_NAMES = ("longitude", "lon", "nav_lon")
_LAT_NAMES = ("latitude", "lat", "nav_lat")
_X_NAMES = ("x", "xc", "projection_x_coordinate")
_Y_NAMES = ("y", "yc", "projection_y_coordinate")


def _find(ds, names, given):
    if given is not None:
        return given if given in ds.variables else None
    for n in names:
        if n in ds.variables:
            return n
    return None


def _span(td) -> str:
    """A time span as ``6 h``, ``1 d 6 h``, ``30 min``."""
    sec = int(td / np.timedelta64(1, "s"))
    d, rem = divmod(sec, 86400)
    h, rem = divmod(rem, 3600)
    m, sec = divmod(rem, 60)
    parts = [f"{v} {u}" for v, u in ((d, "d"), (h, "h"), (m, "min"), (sec, "s")) if v]
    return " ".join(parts) or "0 s"


def _check_spacing(path, tname, tvals) -> None:
    """Records must be evenly spaced (to within a second): a gap (missing records) would be
    interpolated across without a word. Monthly records (every spacing 28 to 31 days) are
    accepted. The expected spacing is the most common one; ForcingError names the file,
    the first record pair that departs from it, their times and spacing."""
    if tvals.size < 3:
        return
    dts = np.diff(tvals)
    vals, counts = np.unique(dts, return_counts=True)
    expected = vals[int(np.argmax(counts))]
    tol = np.timedelta64(1, "s")
    off = np.flatnonzero(np.abs(dts - expected) > tol)
    if not off.size:
        return
    if np.all((dts >= np.timedelta64(28, "D")) & (dts <= np.timedelta64(31, "D"))):
        return  # calendar months
    k = int(off[0])
    what = "a gap (missing records?)" if dts[k] > expected else "records closer than the others"
    raise ForcingError(f"{path}: variable {tname}: records are not evenly spaced: {what} between record {k} "
                       f"({str(tvals[k])[:19]}) and record {k + 1} ({str(tvals[k + 1])[:19]}), {_span(dts[k])} "
                       f"apart, where the records are {_span(expected)} apart; problem: uneven time steps "
                       f"(they would be interpolated across without a word); give evenly spaced records")


def _units_key(units):
    return " ".join(str(units).strip().lower().split())


class GriddedRecords:
    """Record source reading a netCDF file lazily (see module docstring).

    Parameters
    ----------
    path : str or Path
    variables : sequence of str
        One name (scalar) or two names (vector: east/x then north/y).
    quantity : {"wind", "current", "temperature"}
        Sets the accepted units and the plausible range.
    crs : str
        The model's projected CRS (default EPSG:3413, polar stereographic north).
    reference_time : str or numpy.datetime64, optional
        Model time 0; default the first record's time.
    coords : {"auto", "lonlat", "xy"}
        Grid type; "auto" uses lon/lat coordinates if present, else x/y.
    time_name, x_name, y_name : str, optional
        Coordinate names (x/y stand for lon/lat on lon/lat grids); default
        detected among the usual names (time/valid_time, longitude/lon,
        latitude/lat, x/y).
    vector_frame : {"auto", "east_north", "xy"}
        Frame of vector components; "auto": east/north on lon/lat grids,
        x/y on projected grids.
    """

    def __init__(self, path, variables, *, quantity, crs="EPSG:3413", reference_time=None,
                 coords="auto", time_name=None, x_name=None, y_name=None, vector_frame="auto"):
        import xarray as xr

        self.path = str(path)
        self.name = self.path
        self.variables = tuple(variables)
        if len(self.variables) not in (1, 2):
            raise ConfigError(f"{self.path}: give 1 (scalar) or 2 (vector) variable names; "
                              f"got {self.variables}")
        if quantity not in QUANTITIES:
            raise ConfigError(f"quantity = {quantity!r}; expected one of {sorted(QUANTITIES)}")
        if coords not in ("auto", "lonlat", "xy"):
            raise ConfigError(f"coords = {coords!r}; expected 'auto', 'lonlat' or 'xy'")
        if vector_frame not in ("auto", "east_north", "xy"):
            raise ConfigError(f"vector_frame = {vector_frame!r}; expected 'auto', 'east_north' or 'xy'")
        self.quantity = quantity
        unit_table, self.units, self._plausible = QUANTITIES[quantity]
        varlist = ", ".join(self.variables)
        if not Path(self.path).is_file():
            raise ForcingError(f"{self.path}: variable {varlist}: file not found")
        try:
            ds = xr.open_dataset(self.path)
        except Exception as exc:
            raise ForcingError(f"{self.path}: variable {varlist}: cannot open as netCDF "
                               f"with a CF time axis ({type(exc).__name__}: {exc})") from None
        self._ds = ds

        # --- variables and units
        self._scale = []
        for v in self.variables:
            if v not in ds.data_vars:
                raise ForcingError(f"{self.path}: variable {v}: not in the file "
                                   f"(file has: {', '.join(map(str, ds.data_vars)) or 'nothing'}); "
                                   f"problem: missing variable")
            units = ds[v].attrs.get("units", ds[v].encoding.get("units"))
            if units is None:
                raise ForcingError(f"{self.path}: variable {v}: no 'units' attribute; "
                                   f"problem: missing units (expected {self.units})")
            key = _units_key(units)
            if key not in {_units_key(k) for k in unit_table}:
                raise ForcingError(f"{self.path}: variable {v}: units {units!r} are not "
                                   f"{quantity} units; problem: wrong units (expected e.g. "
                                   f"{', '.join(list(unit_table)[:4])})")
            self._scale.append(next(val for k, val in unit_table.items() if _units_key(k) == key))

        # --- time
        tname = _find(ds, _TIME_NAMES, time_name)
        if tname is None:
            raise ForcingError(f"{self.path}: variable {varlist}: no time coordinate "
                               f"(looked for {time_name or _TIME_NAMES}); problem: missing time")
        tvals = ds[tname].values
        if tvals.dtype.kind == "O":
            try:
                tvals = ds.indexes[tname].to_datetimeindex().values
            except Exception:
                raise ForcingError(f"{self.path}: variable {tname}: time values cannot be decoded "
                                   f"to dates; problem: time is not a CF time coordinate") from None
        if tvals.dtype.kind != "M":
            raise ForcingError(f"{self.path}: variable {tname}: time has no CF units "
                               f"('hours since YYYY-MM-DD ...'); problem: time is not a CF time "
                               f"coordinate")
        tvals = tvals.astype("datetime64[ns]")
        if tvals.size > 1:
            bad = np.flatnonzero(np.diff(tvals) <= np.timedelta64(0, "ns"))
            if bad.size:
                k = int(bad[0]) + 1
                raise ForcingError(f"{self.path}: variable {tname}: time is not strictly increasing "
                                   f"(record {k} at {tvals[k]} follows {tvals[k - 1]}); problem: "
                                   f"time not monotonic")
        _check_spacing(self.path, tname, tvals)
        if reference_time is None:
            ref = tvals[0]
        else:
            try:
                ref = np.datetime64(reference_time, "ns")
            except Exception:
                raise ConfigError(f"reference_time = {reference_time!r} is not a date") from None
        self.reference_time = ref
        self.record_times = tvals
        self.times_s = (tvals - ref) / np.timedelta64(1, "s")
        self._tname = tname

        # --- grid
        lon = _find(ds, _LON_NAMES, x_name if coords == "lonlat" else None)
        lat = _find(ds, _LAT_NAMES, y_name if coords == "lonlat" else None)
        xn = _find(ds, _X_NAMES, x_name if coords == "xy" else None)
        yn = _find(ds, _Y_NAMES, y_name if coords == "xy" else None)
        if coords == "auto" and (x_name or y_name):
            raise ConfigError("give coords='lonlat' or 'xy' together with x_name/y_name")
        use_lonlat = coords == "lonlat" or (coords == "auto" and lon is not None and lat is not None)
        if use_lonlat:
            if lon is None or lat is None:
                raise ForcingError(f"{self.path}: variable {varlist}: no longitude/latitude "
                                   f"coordinates; problem: missing grid coordinates")
            xc, yc = lon, lat
        else:
            if xn is None or yn is None:
                raise ForcingError(f"{self.path}: variable {varlist}: no lon/lat or x/y "
                                   f"coordinates; problem: missing grid coordinates")
            xc, yc = xn, yn
        self._xname, self._yname = xc, yc
        xv = np.asarray(ds[xc].values, dtype=np.float64)
        yv = np.asarray(ds[yc].values, dtype=np.float64)
        if xv.ndim != 1 or yv.ndim != 1:
            raise ForcingError(f"{self.path}: variable {xc}/{yc}: 2-D coordinates are not "
                               f"supported; problem: grid must be regular lon/lat or x/y")
        if not use_lonlat:
            for cname in (xc, yc):
                u = ds[cname].attrs.get("units")
                if u is None or _units_key(u) not in LENGTH_UNITS:
                    raise ForcingError(f"{self.path}: variable {cname}: coordinate units {u!r}; "
                                       f"problem: {'missing' if u is None else 'wrong'} units "
                                       f"(expected m or km)")
            xv = xv * LENGTH_UNITS[_units_key(ds[xc].attrs["units"])]
            yv = yv * LENGTH_UNITS[_units_key(ds[yc].attrs["units"])]
        if use_lonlat:
            xv = np.where(xv > 180.0 + 1e-9, xv - 360.0, xv) if np.any(np.diff(xv) <= 0) else xv
        self._xorder = np.argsort(xv, kind="stable")
        self._yorder = np.argsort(yv, kind="stable")
        if use_lonlat and xv.size > 2 and xv[self._xorder[-1]] - xv[self._xorder[0]] >= 360.0 - 1e-9:
            self._xorder = self._xorder[:-1]  # duplicated 360° column (e.g. 0..360)
        xs, ys = xv[self._xorder], yv[self._yorder]
        self._xsorted = bool(self._xorder.size == xv.size and np.all(self._xorder == np.arange(xv.size)))
        self._ysorted = bool(np.all(self._yorder == np.arange(yv.size)))
        if use_lonlat:
            self.grid = LonLatGrid(xs, ys, crs=crs, name=f"{self.path}: variable {xc}/{yc}")
        else:
            self.grid = RegularGrid(xs, ys, name=f"{self.path}: variable {xc}/{yc}")
        self.lonlat = use_lonlat
        if vector_frame == "auto":
            vector_frame = "east_north" if use_lonlat else "xy"
        if vector_frame == "east_north" and not use_lonlat:
            raise ConfigError(f"{self.path}: vector_frame='east_north' needs a lon/lat grid")
        self.vector_frame = vector_frame

        # --- dimensions of each variable: (time, y, x) after squeezing size-1 dims
        xdim, ydim = ds[xc].dims[0], ds[yc].dims[0]
        tdim = ds[tname].dims[0] if ds[tname].dims else tname
        self._das = []
        for v in self.variables:
            da = ds[v]
            extra = [d for d in da.dims if d not in (tdim, ydim, xdim)]
            for d in extra:
                if da.sizes[d] != 1:
                    raise ForcingError(f"{self.path}: variable {v}: extra dimension {d} of size "
                                       f"{da.sizes[d]}; problem: expected dims ({tdim}, {ydim}, {xdim})")
                da = da.isel({d: 0})
            if set(da.dims) != {tdim, ydim, xdim}:
                raise ForcingError(f"{self.path}: variable {v}: dims {da.dims}; problem: expected "
                                   f"({tdim}, {ydim}, {xdim})")
            self._das.append(da.transpose(tdim, ydim, xdim))
        self._tdim = tdim

    @property
    def n_components(self):
        return len(self.variables)

    def describe_time(self, i):
        return f"record {i} ({str(self.record_times[i])[:19]})"

    def read(self, i):
        """Record ``i`` as ``(nc, ny, nx)`` float64 in model units, sorted
        grid order, vector components in the projected x/y frame."""
        out = np.empty((len(self.variables),) + self.grid.shape)
        for c, (da, (scale, offset)) in enumerate(zip(self._das, self._scale)):
            a = np.asarray(da.isel({self._tdim: i}).values, dtype=np.float64)
            if not self._ysorted:
                a = a[self._yorder]
            if not self._xsorted:
                a = a[:, self._xorder]
            a = np.where(np.abs(a) > FILL_THRESHOLD, np.nan, a)
            a = a * scale + offset
            lo, hi = self._plausible
            if np.any(a < lo) or np.any(a > hi):
                raise ForcingError(
                    f"{self.path}: variable {self.variables[c]}: values in "
                    f"[{np.nanmin(a):.4g}, {np.nanmax(a):.4g}] {self.units} in {self.describe_time(i)} "
                    f"after unit conversion; problem: implausible values (wrong units?), expected "
                    f"within [{lo}, {hi}] {self.units}")
            out[c] = a
        if len(self.variables) == 2 and self.vector_frame == "east_north":
            out[0], out[1] = self.grid.rotate_east_north(out[0], out[1])
        return out

    def close(self):
        self._ds.close()


def open_gridded(path, variables, *, quantity, crs="EPSG:3413", reference_time=None,
                 coords="auto", time_name=None, x_name=None, y_name=None, vector_frame="auto",
                 time_extrapolation="error", space_extrapolation="error", rebuild_tolerance_m=0.0):
    """A :class:`RecordField` reading ``variables`` from the netCDF file ``path``.

    See :class:`GriddedRecords` for the file arguments and
    :class:`forcing.records.RecordField` for the interpolation arguments.
    """
    if isinstance(variables, str):
        variables = (variables,)
    src = GriddedRecords(path, variables, quantity=quantity, crs=crs, reference_time=reference_time,
                         coords=coords, time_name=time_name, x_name=x_name, y_name=y_name,
                         vector_frame=vector_frame)
    return RecordField(src, time_extrapolation=time_extrapolation,
                       space_extrapolation=space_extrapolation,
                       rebuild_tolerance_m=rebuild_tolerance_m)


def open_wind(path, u="u10", v="v10", **kwargs):
    """10 m wind [m s-1] from a file (ERA5 names ``u10``, ``v10`` by default)."""
    return open_gridded(path, (u, v), quantity="wind", **kwargs)


def open_air_temperature(path, name="t2m", **kwargs):
    """2 m air temperature [°C] from a file (ERA5 name ``t2m`` in K by default)."""
    return open_gridded(path, (name,), quantity="temperature", **kwargs)


def open_ocean_current(path, u="uo", v="vo", **kwargs):
    """Surface ocean current [m s-1] from a file (CMEMS names ``uo``, ``vo`` by default)."""
    return open_gridded(path, (u, v), quantity="current", **kwargs)
