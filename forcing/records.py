"""Record-based forcing: time and space interpolation (docs/design.md §6).

Forcing data come as *records*: complete 2-D fields on a fixed grid, one per
record time (every 6 h by default, any strictly increasing times allowed).
:class:`RecordField` evaluates them at model time ``t`` and current positions
``x, y``:

* **time**: linear between the two bracketing records ``i, i+1``,
  ``f = (1 - a) f_i + a f_{i+1}``, ``a = (t - t_i) / (t_{i+1} - t_i)``;
  a source with a single record is steady (valid at all times);
* **space**: bilinear on the record grid (a rectilinear x/y grid in metres,
  :class:`RegularGrid`, or a lon/lat grid in degrees, :class:`LonLatGrid`,
  onto which positions are mapped with pyproj).

Caching (what costs what)
-------------------------
* The two bracketing records are read once and kept in memory; moving to the
  next pair reads one new record.  Files are never re-read for the weights.
* Bilinear weights (cell index and fractions per point, plus the pyproj
  inverse projection for lon/lat grids) are cached and rebuilt only when the
  positions change.  Rebuild trigger, in order:

  1. number of points changed, or first call → rebuild;
  2. ``mesh_version`` given and equal to the one of the previous call →
     no rebuild, no check (cheapest: the caller promises the positions did
     not change, e.g. a second evaluation in the same step);
  3. ``mesh_version`` given and changed, ``rebuild_tolerance_m == 0`` →
     rebuild (no comparison);
  4. otherwise (no ``mesh_version``, or a tolerance > 0) the positions are
     compared with the copy taken at the last build (one O(n) pass):
     rebuild if any node moved by more than ``rebuild_tolerance_m``
     (default 0: any change, including in-place moves).  With a tolerance
     > 0, values are taken at positions at most that far from the current
     ones (error ≤ |∇f|·tolerance), which saves rebuilds when the ice
     drifts slowly compared with the grid spacing (worth it for lon/lat
     grids, whose rebuild is dominated by the pyproj projection).

  A Lagrangian mesh moves every step, so with the default tolerance weights
  are rebuilt once per step per field: that rebuild is a compiled O(n) kernel
  (plus one pyproj call for lon/lat grids), see ``benchmarks/bench_forcing.py``.
* Evaluation is one compiled, parallel O(n) gather (8 reads per point and
  component) that also counts non-finite values, so NaN or fill values met at
  run time raise :class:`ForcingError` without an extra pass.
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from lagice.errors import ConfigError, ForcingError

from ._numba_util import pick, serial_and_parallel
from .base import SCALAR, VECTOR, Field

HOUR_S = 3600.0
DAY_S = 86400.0


# ----------------------------------------------------------------------------
# kernels
# ----------------------------------------------------------------------------
@njit(cache=True)
def _cell(ax, p, uniform, inv_d):
    """Index i of the cell ``[ax[i], ax[i+1]]`` holding ``p`` (p inside the axis):
    arithmetic on a uniform axis, binary search otherwise."""
    n = ax.shape[0]
    if uniform:
        i = int((p - ax[0]) * inv_d)
        if i > n - 2:
            i = n - 2
        if i < 0:
            i = 0
        if p < ax[i] and i > 0:  # round-off at cell edges
            i -= 1
        elif p >= ax[i + 1] and i < n - 2:
            i += 1
        return i
    i = np.searchsorted(ax, p, side="right") - 1
    if i > n - 2:
        i = n - 2
    if i < 0:
        i = 0
    return i


def _bilinear_weights(gx, gy, ax, ay, ux, uy, clamp, i0, j0, fx, fy):
    """Cell indices ``i0, j0`` and fractions ``fx, fy`` in [0, 1] of points
    ``(gx, gy)`` on the rectilinear grid with increasing axes ``ax, ay``
    (``ux, uy``: axis uniform?).

    Returns the number of points outside the grid (or non-finite); with
    ``clamp`` those are moved to the nearest grid edge instead.
    """
    n = gx.shape[0]
    nx = ax.shape[0]
    ny = ay.shape[0]
    inv_dx = (nx - 1) / (ax[nx - 1] - ax[0])
    inv_dy = (ny - 1) / (ay[ny - 1] - ay[0])
    n_out = 0
    for k in prange(n):
        px = gx[k]
        py = gy[k]
        bad = 0
        if not (px >= ax[0] and px <= ax[nx - 1]):
            bad = 1
            if px > ax[nx - 1]:
                px = ax[nx - 1]
            else:
                px = ax[0]
        if not (py >= ay[0] and py <= ay[ny - 1]):
            bad = 1
            if py > ay[ny - 1]:
                py = ay[ny - 1]
            else:
                py = ay[0]
        n_out += bad
        i = _cell(ax, px, ux, inv_dx)
        j = _cell(ay, py, uy, inv_dy)
        i0[k] = i
        j0[k] = j
        fx[k] = (px - ax[i]) / (ax[i + 1] - ax[i])
        fy[k] = (py - ay[j]) / (ay[j + 1] - ay[j])
    if clamp:
        return 0
    return n_out


@njit(cache=True, inline="always")
def _bilinear(r, c, i, j, wx, wy):
    """Bilinear value of component ``c`` of record ``r (nc, ny, nx)`` in cell (i, j)."""
    return ((1.0 - wx) * (1.0 - wy) * r[c, j, i] + wx * (1.0 - wy) * r[c, j, i + 1]
            + (1.0 - wx) * wy * r[c, j + 1, i] + wx * wy * r[c, j + 1, i + 1])


def _interp_records(r0, r1, a, i0, j0, fx, fy, out):
    """``out[c, k] = (1-a)·bilinear(r0[c])(k) + a·bilinear(r1[c])(k)``.

    ``r0, r1``: records ``(nc, ny, nx)``; returns the count of non-finite
    results (NaN/fill values met in the records).
    """
    n_bad = 0
    for k in prange(i0.shape[0]):
        bad = 0
        for c in range(r0.shape[0]):
            v = ((1.0 - a) * _bilinear(r0, c, i0[k], j0[k], fx[k], fy[k])
                 + a * _bilinear(r1, c, i0[k], j0[k], fx[k], fy[k]))
            if not np.isfinite(v):
                bad = 1
            out[c, k] = v
        n_bad += bad
    return n_bad


def _interp_record(r, i0, j0, fx, fy, out):
    """``out[c, k] = bilinear(r[c])(k)`` for one record ``(nc, ny, nx)``;
    returns the count of non-finite results."""
    n_bad = 0
    for k in prange(i0.shape[0]):
        bad = 0
        for c in range(r.shape[0]):
            v = _bilinear(r, c, i0[k], j0[k], fx[k], fy[k])
            if not np.isfinite(v):
                bad = 1
            out[c, k] = v
        n_bad += bad
    return n_bad


def _max_abs_diff(x, y, xc, yc):
    """max_k max(|x_k - xc_k|, |y_k - yc_k|) [m] (inf if a value is NaN)."""
    n = x.shape[0]
    m = 0.0
    for k in prange(n):
        d = max(abs(x[k] - xc[k]), abs(y[k] - yc[k]))
        if not d <= 1e300:
            d = np.inf
        m = max(m, d)
    return m


_BILINEAR_WEIGHTS = serial_and_parallel(_bilinear_weights)
_INTERP_RECORDS = serial_and_parallel(_interp_records)
_INTERP_RECORD = serial_and_parallel(_interp_record)
_MAX_ABS_DIFF = serial_and_parallel(_max_abs_diff)


# ----------------------------------------------------------------------------
# grids
# ----------------------------------------------------------------------------
def _check_axis(name, axis, where):
    axis = np.asarray(axis, dtype=np.float64)
    if axis.ndim != 1 or axis.size < 2:
        raise ForcingError(f"{where}: coordinate {name} must be 1-D with at least 2 values; "
                           f"got shape {axis.shape}")
    if not np.all(np.isfinite(axis)):
        raise ForcingError(f"{where}: coordinate {name} has non-finite values")
    if not np.all(np.diff(axis) > 0):
        raise ForcingError(f"{where}: coordinate {name} is not strictly monotonic")
    return axis


class RegularGrid:
    """Rectilinear grid in the model's projected plane.

    Parameters
    ----------
    x_m, y_m : array_like
        Strictly increasing cell-vertex coordinates [m]; records are arrays
        of shape ``(ny, nx)`` (row = y).
    """

    periodic_x = False

    def __init__(self, x_m, y_m, name="<grid>"):
        self.x_m = _check_axis("x", x_m, name)
        self.y_m = _check_axis("y", y_m, name)
        self.shape = (self.y_m.size, self.x_m.size)

    @classmethod
    def from_bbox(cls, xmin, xmax, ymin, ymax, spacing_m, margin_m=None):
        """Grid covering the box ``[xmin, xmax] × [ymin, ymax]`` [m] plus a
        margin (default two spacings, so a drifting mesh stays inside)
        at spacing ``spacing_m`` (rounded so the box is covered exactly)."""
        if not spacing_m > 0:
            raise ConfigError(f"grid spacing_m = {spacing_m!r} must be > 0")
        if not (xmax > xmin and ymax > ymin):
            raise ConfigError(f"bounding box ({xmin}, {xmax}, {ymin}, {ymax}) m is empty")
        margin = 2.0 * spacing_m if margin_m is None else float(margin_m)
        axes = []
        for lo, hi in ((xmin - margin, xmax + margin), (ymin - margin, ymax + margin)):
            n = max(2, int(np.ceil((hi - lo) / spacing_m)) + 1)
            axes.append(np.linspace(lo, hi, n))
        return cls(axes[0], axes[1])

    @property
    def axes(self):
        """Interpolation axes ``(ax, ay)``."""
        return self.x_m, self.y_m

    def grid_coords(self, x, y):
        """Positions ``x, y`` [m] in grid coordinates (identity here)."""
        return np.ascontiguousarray(x, dtype=np.float64), np.ascontiguousarray(y, dtype=np.float64)

    def extend(self, record):
        """Record as used by the interpolation (identity here)."""
        return record

    def mesh(self):
        """2-D coordinate arrays ``(X, Y)`` of shape ``(ny, nx)`` [m]."""
        return np.meshgrid(self.x_m, self.y_m)


class LonLatGrid:
    """Regular longitude/latitude grid seen from the model's projected CRS.

    Parameters
    ----------
    lon_deg : array_like
        Strictly increasing longitudes [degrees east] (any 360° window,
        e.g. -180..177.5 or 0..359); a grid closing the globe
        (``lon[-1] + Δlon = lon[0] + 360``) is treated as periodic.
    lat_deg : array_like
        Strictly increasing latitudes [degrees north] (a file with
        decreasing latitudes is flipped by its reader).
    crs : str
        The model's projected CRS (default polar stereographic EPSG:3413).

    Notes
    -----
    Positions are mapped to lon/lat with pyproj (cached with the weights by
    :class:`RecordField`), then interpolated bilinearly in (lon, lat).
    Vector components given east/north are rotated into the projected x/y
    frame once per record, at the grid points (:meth:`rotation`), so that
    what is interpolated are the x/y components, which stay smooth near the
    pole where east/north components do not.
    """

    def __init__(self, lon_deg, lat_deg, crs="EPSG:3413", name="<grid>"):
        from pyproj import CRS, Transformer

        self.lon_deg = _check_axis("longitude", lon_deg, name)
        self.lat_deg = _check_axis("latitude", lat_deg, name)
        if self.lon_deg[-1] - self.lon_deg[0] >= 360.0:
            raise ForcingError(f"{name}: longitudes span {self.lon_deg[-1] - self.lon_deg[0]}° >= 360°")
        if self.lat_deg[0] < -90 or self.lat_deg[-1] > 90:
            raise ForcingError(f"{name}: latitudes outside [-90, 90]°")
        try:
            self.crs = CRS.from_user_input(crs)
        except Exception as exc:  # pyproj raises CRSError
            raise ConfigError(f"crs = {crs!r} is not a valid CRS ({exc})") from None
        self._to_lonlat = Transformer.from_crs(self.crs, "EPSG:4326", always_xy=True)
        self._to_xy = Transformer.from_crs("EPSG:4326", self.crs, always_xy=True)
        self.shape = (self.lat_deg.size, self.lon_deg.size)
        dlon = np.diff(self.lon_deg)
        self.periodic_x = bool(np.allclose(dlon, dlon[0], rtol=1e-6)
                               and abs(self.lon_deg[-1] + dlon[0] - self.lon_deg[0] - 360.0) < 1e-6)
        lon_axis = self.lon_deg
        if self.periodic_x:
            lon_axis = np.append(lon_axis, self.lon_deg[0] + 360.0)
        self._lon_axis = lon_axis
        self._rotation = None

    @property
    def axes(self):
        """Interpolation axes ``(lon, lat)`` [deg] (lon closed when periodic)."""
        return self._lon_axis, self.lat_deg

    def grid_coords(self, x, y):
        """Positions ``x, y`` [m] → ``(lon, lat)`` [deg], lon wrapped into the
        grid's 360° window starting at ``lon[0]``."""
        lon, lat = self._to_lonlat.transform(np.asarray(x, dtype=np.float64),
                                             np.asarray(y, dtype=np.float64))
        lon = np.asarray(lon, dtype=np.float64)
        lon0 = self.lon_deg[0]
        lon = lon0 + np.mod(lon - lon0, 360.0)
        return np.ascontiguousarray(lon), np.ascontiguousarray(lat, dtype=np.float64)

    def extend(self, record):
        """Append the wrap-around column to a record ``(nc, nlat, nlon)`` when periodic."""
        if not self.periodic_x:
            return record
        return np.concatenate([record, record[..., :1]], axis=-1)

    def rotation(self):
        """Angle θ [rad] per grid point ``(nlat, nlon)`` such that the local
        east and north unit vectors in the projected plane are
        ``(cos θ, sin θ)`` and ``(-sin θ, cos θ)``.

        Computed with pyproj by projecting a small northward step (southward
        at the pole); the CRS is assumed conformal (true for EPSG:3413, where
        θ = lon − (−45°), so northward wind is +y at lon −45° and −x at 45°).
        """
        if self._rotation is None:
            lon, lat = np.meshgrid(self.lon_deg, self.lat_deg)
            step = np.where(lat > 89.0, -1e-3, 1e-3)
            x0, y0 = self._to_xy.transform(lon, lat)
            x1, y1 = self._to_xy.transform(lon, lat + step)
            sgn = np.sign(step)
            dx = (np.asarray(x1) - np.asarray(x0)) * sgn
            dy = (np.asarray(y1) - np.asarray(y0)) * sgn
            self._rotation = np.arctan2(-dx, dy)
        return self._rotation

    def rotate_east_north(self, u_east, v_north):
        """Rotate east/north components (grid arrays) into projected x/y components."""
        th = self.rotation()
        c, s = np.cos(th), np.sin(th)
        return u_east * c - v_north * s, u_east * s + v_north * c


# ----------------------------------------------------------------------------
# record sources
# ----------------------------------------------------------------------------
class InMemoryRecords:
    """Records held in memory (synthetic generators produce these).

    Parameters
    ----------
    times_s : array_like, shape (nt,)
        Record times [s since the run's reference time], strictly increasing;
        a single record is steady (valid at all times).
    grid : RegularGrid or LonLatGrid
    data : array_like, shape (nt, nc, ny, nx)
        ``nc = 1`` for a scalar field, 2 for a vector field (x/y components).
    variables : tuple of str
        Names of the components (used in messages and netCDF output).
    units : str
    name : str
        Where the records come from (used in messages).
    """

    def __init__(self, times_s, grid, data, variables, units="", name="<records>"):
        self.name = name
        self.times_s = _check_axis("time", np.atleast_1d(times_s), name) if np.size(times_s) > 1 \
            else np.asarray(np.atleast_1d(times_s), dtype=np.float64)
        self.grid = grid
        data = np.asarray(data, dtype=np.float64)
        if data.ndim != 4 or data.shape[0] != self.times_s.size or data.shape[2:] != grid.shape:
            raise ConfigError(f"{name}: records of shape {data.shape} do not match "
                              f"(nt={self.times_s.size}, nc, {grid.shape[0]}, {grid.shape[1]})")
        self.data = data
        self.variables = tuple(variables)
        if len(self.variables) != data.shape[1]:
            raise ConfigError(f"{name}: {len(self.variables)} variable names for {data.shape[1]} components")
        self.units = units

    @property
    def n_components(self):
        return self.data.shape[1]

    def read(self, i):
        """Record ``i`` as ``(nc, ny, nx)`` float64 (a view, not a copy)."""
        return self.data[i]

    def describe_time(self, i):
        return f"record {i} (t = {self.times_s[i]:.0f} s)"

    def to_netcdf(self, path, reference_time="2000-01-01T00:00:00"):
        """Write the records as a CF netCDF file readable by
        :func:`forcing.gridded.open_gridded` (x/y grids only)."""
        import xarray as xr

        if not isinstance(self.grid, RegularGrid):
            raise ConfigError("to_netcdf writes projected x/y grids only")
        ref = np.datetime64(reference_time, "ns")
        time = ref + (self.times_s * 1e9).astype("timedelta64[ns]")
        ds = xr.Dataset(
            {v: (("time", "y", "x"), self.data[:, c], {"units": self.units})
             for c, v in enumerate(self.variables)},
            coords={"time": ("time", time),
                    "x": ("x", self.grid.x_m, {"units": "m"}),
                    "y": ("y", self.grid.y_m, {"units": "m"})})
        ds.to_netcdf(path, encoding={"time": {"units": f"hours since {reference_time}"}})
        return path


# ----------------------------------------------------------------------------
# the field
# ----------------------------------------------------------------------------
class RecordField(Field):
    """A scalar or vector field interpolated from records (see module docstring).

    Parameters
    ----------
    source : InMemoryRecords or forcing.gridded.GriddedRecords
        Provides ``times_s``, ``grid``, ``variables``, ``n_components``,
        ``read(i)`` and ``describe_time(i)``.
    time_extrapolation : {"error", "hold"}
        Outside the record times: raise :class:`ForcingError` (default), or
        opt-in hold the first/last record constant.
    space_extrapolation : {"error", "clamp"}
        Points outside the grid: raise (default), or opt-in take the value
        at the nearest grid edge.
    rebuild_tolerance_m : float
        Node displacement [m] since the last weight build that triggers a
        rebuild when ``mesh_version`` does not rule it out (default 0).
    """

    def __init__(self, source, *, time_extrapolation="error", space_extrapolation="error",
                 rebuild_tolerance_m=0.0):
        if time_extrapolation not in ("error", "hold"):
            raise ConfigError(f"time_extrapolation = {time_extrapolation!r}; expected 'error' or 'hold'")
        if space_extrapolation not in ("error", "clamp"):
            raise ConfigError(f"space_extrapolation = {space_extrapolation!r}; expected 'error' or 'clamp'")
        if not rebuild_tolerance_m >= 0:
            raise ConfigError(f"rebuild_tolerance_m = {rebuild_tolerance_m!r} must be >= 0")
        nc = source.n_components
        if nc not in (1, 2):
            raise ConfigError(f"{source.name}: {nc} components; expected 1 (scalar) or 2 (vector)")
        self.source = source
        self.grid = source.grid
        self.kind = SCALAR if nc == 1 else VECTOR
        self.units = getattr(source, "units", "")
        self.name = source.name
        self.time_extrapolation = time_extrapolation
        self.space_extrapolation = space_extrapolation
        self.rebuild_tolerance_m = float(rebuild_tolerance_m)
        self._ax, self._ay = (np.ascontiguousarray(a) for a in self.grid.axes)
        self._uniform = tuple(
            bool(np.allclose(np.diff(a), (a[-1] - a[0]) / (a.size - 1), rtol=1e-9, atol=0.0))
            for a in (self._ax, self._ay))
        self._blend = None  # (i, j, a, record blended in time on the grid)
        self._records = {}
        self._weights = None
        self._version = None
        self._pos = None
        #: number of weight builds and record reads so far (diagnostics).
        self.n_weight_builds = 0
        self.n_record_reads = 0

    # -- messages ---------------------------------------------------------
    def _where(self, comp=None):
        var = ", ".join(self.source.variables) if comp is None else self.source.variables[comp]
        return f"{self.source.name}: variable {var}"

    # -- weights ----------------------------------------------------------
    def _build_weights(self, x, y):
        n = x.shape[0]
        gx, gy = self.grid.grid_coords(x, y)
        if self._weights is not None and self._weights[0].shape[0] == n:
            i0, j0, fx, fy = self._weights  # reuse the arrays
        else:
            i0 = np.empty(n, np.int64)
            j0 = np.empty(n, np.int64)
            fx = np.empty(n)
            fy = np.empty(n)
        self._weights = None
        clamp = self.space_extrapolation == "clamp"
        n_out = pick(_BILINEAR_WEIGHTS, n)(gx, gy, self._ax, self._ay, *self._uniform, clamp,
                                           i0, j0, fx, fy)
        if n_out:
            inside = ((gx >= self._ax[0]) & (gx <= self._ax[-1])
                      & (gy >= self._ay[0]) & (gy <= self._ay[-1]))
            k = int(np.flatnonzero(~inside)[0])
            raise ForcingError(
                f"{self._where()}: {n_out} of {n} points lie outside the forcing grid "
                f"(first: point {k} at x = {x[k]:.1f} m, y = {y[k]:.1f} m → grid coordinates "
                f"({gx[k]:.4g}, {gy[k]:.4g}); grid covers [{self._ax[0]:.4g}, {self._ax[-1]:.4g}] × "
                f"[{self._ay[0]:.4g}, {self._ay[-1]:.4g}]); problem: mesh outside the grid "
                f"(use space_extrapolation='clamp' to opt in to edge values)")
        self._weights = (i0, j0, fx, fy)
        if self._pos is not None and self._pos[0].shape == x.shape:
            self._pos[0][:] = x
            self._pos[1][:] = y
        else:
            self._pos = (x.copy(), y.copy())
        self.n_weight_builds += 1

    def _ensure_weights(self, x, y, mesh_version):
        x = np.ascontiguousarray(x, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        if x.shape != y.shape or x.ndim != 1:
            raise ConfigError(f"positions x, y must be 1-D arrays of equal shape; got {x.shape}, {y.shape}")
        if self._weights is None or self._pos[0].shape != x.shape:
            self._build_weights(x, y)
        elif mesh_version is not None and mesh_version == self._version:
            pass
        elif mesh_version is not None and self.rebuild_tolerance_m == 0.0:
            self._build_weights(x, y)  # new version, exact weights wanted: skip the comparison
        else:
            moved = pick(_MAX_ABS_DIFF, x.shape[0])(x, y, self._pos[0], self._pos[1])
            if moved > self.rebuild_tolerance_m:
                self._build_weights(x, y)
        self._version = mesh_version
        return self._weights

    def invalidate_weights(self):
        """Forget the cached weights (next evaluation rebuilds them)."""
        self._weights = None
        self._version = None
        self._pos = None

    def weight_positions(self):
        """Copies ``(x, y)`` [m] of the positions the cached weights were built
        at, or ``None`` (store in a checkpoint when ``rebuild_tolerance_m > 0``)."""
        return None if self._pos is None else (self._pos[0].copy(), self._pos[1].copy())

    def restore_weight_positions(self, positions):
        """Rebuild the weights at positions saved by :meth:`weight_positions`, so
        that a resumed run with ``rebuild_tolerance_m > 0`` is bit-identical to
        the uninterrupted one (with the default tolerance 0 nothing is needed)."""
        self.invalidate_weights()
        if positions is not None:
            self._build_weights(np.ascontiguousarray(positions[0], dtype=np.float64),
                                np.ascontiguousarray(positions[1], dtype=np.float64))

    # -- records ----------------------------------------------------------
    def _bracket(self, t):
        times = self.source.times_s
        nt = times.size
        if nt == 1:
            return 0, 0, 0.0
        t = float(t)
        if not (times[0] <= t <= times[-1]):
            if self.time_extrapolation == "hold" and np.isfinite(t):
                return (0, 0, 0.0) if t < times[0] else (nt - 1, nt - 1, 0.0)
            raise ForcingError(
                f"{self._where()}: run time t = {t} s is outside the records "
                f"[{times[0]}, {times[-1]}] s ({self.source.describe_time(0)} .. "
                f"{self.source.describe_time(nt - 1)}); problem: run times outside the records "
                f"(use time_extrapolation='hold' to opt in)")
        i = int(np.searchsorted(times, t, side="right")) - 1
        i = min(max(i, 0), nt - 2)
        a = (t - times[i]) / (times[i + 1] - times[i])
        return i, i + 1, a

    def _record(self, i):
        rec = self._records.get(i)
        if rec is None:
            rec = np.ascontiguousarray(self.grid.extend(self.source.read(i)), dtype=np.float64)
            self.n_record_reads += 1
            self._records[i] = rec
        return rec

    def _pair(self, i, j):
        r0 = self._record(i)
        r1 = self._record(j)
        for k in list(self._records):
            if k != i and k != j:
                del self._records[k]
                self._blend = None
        return r0, r1

    # -- Field interface --------------------------------------------------
    def evaluate(self, t, x, y, *, mesh_version=None, out=None):
        """Values at time ``t`` [s] and positions ``x, y`` [m]: ``(n,)`` for a
        scalar, ``(2, n)`` for a vector field (see module docstring for the
        caching and the rebuild trigger)."""
        i0, j0, fx, fy = self._ensure_weights(x, y, mesh_version)
        i, j, a = self._bracket(t)
        r0, r1 = self._pair(i, j)
        n = i0.shape[0]
        nc = r0.shape[0]
        if out is None:
            out = np.empty((n,) if nc == 1 else (nc, n))
        out2 = out.reshape(nc, n)
        if i == j or a == 0.0:
            n_bad = pick(_INTERP_RECORD, n)(r0, i0, j0, fx, fy, out2)
        elif r0.size <= nc * n:
            # grid smaller than the points: blend in time on the grid once per
            # time (cached), then one 4-point gather per point
            if self._blend is None or self._blend[:3] != (i, j, a):
                self._blend = (i, j, a, (1.0 - a) * r0 + a * r1)
            n_bad = pick(_INTERP_RECORD, n)(self._blend[3], i0, j0, fx, fy, out2)
        else:
            n_bad = pick(_INTERP_RECORDS, n)(r0, r1, a, i0, j0, fx, fy, out2)
        if n_bad:
            self._raise_nonfinite(out.reshape(nc, n), t, i, j)
        return out

    def _raise_nonfinite(self, vals, t, i, j):
        comp = int(np.flatnonzero(~np.all(np.isfinite(vals), axis=1))[0])
        raise ForcingError(
            f"{self._where(comp)}: NaN or fill values inside the domain at t = {t} s "
            f"(between {self.source.describe_time(i)} and {self.source.describe_time(j)}); "
            f"problem: missing data where the mesh is")

    def prepare(self, t_start, t_end, x, y):
        """Check coverage before a run: record times cover ``[t_start, t_end]``
        (unless 'hold'), all points inside the grid (unless 'clamp'), and no
        NaN/fill value in any record of the run window over the grid box
        holding the points (plus one cell)."""
        self._bracket(t_start)
        self._bracket(t_end)
        x = np.ascontiguousarray(x, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        self._build_weights(x, y)
        self._version = None
        i0, j0, _, _ = self._weights
        if i0.size == 0:
            return
        ilo, ihi = max(int(i0.min()) - 1, 0), int(i0.max()) + 3
        jlo, jhi = max(int(j0.min()) - 1, 0), int(j0.max()) + 3
        times = self.source.times_s
        if times.size == 1:
            idx = [0]
        else:
            k0 = self._bracket(max(min(t_start, times[-1]), times[0]))[0]
            k1 = self._bracket(max(min(t_end, times[-1]), times[0]))[1]
            idx = range(k0, k1 + 1)
        for k in idx:
            rec = self.grid.extend(self.source.read(k))[:, jlo:jhi, ilo:ihi]
            finite = np.isfinite(rec)
            if not finite.all():
                comp = int(np.flatnonzero(~finite.reshape(finite.shape[0], -1).all(axis=1))[0])
                raise ForcingError(
                    f"{self._where(comp)}: NaN or fill values inside the domain in "
                    f"{self.source.describe_time(k)} ({int((~finite).sum())} grid values over the "
                    f"mesh box); problem: missing data where the mesh is")
