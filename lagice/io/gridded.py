"""Optional regular-grid output: conservative (area-weighted) averages of
element fields on a projected x/y grid, with a CF grid mapping.

Each grid cell receives Σ_e v_e |e ∩ cell| / Σ_e |e ∩ cell| over the
triangles e that overlap it; the overlap areas are exact (each triangle is
clipped against the cell rectangle, Sutherland–Hodgman). ``coverage`` is the
fraction of the cell covered by the mesh; cells with no ice mesh at all
(land, outside the domain) hold NaN, declared as ``_FillValue`` and
explained in the variable's ``comment`` — no other value is filled.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _clip_area(px, py, n, x0, x1, y0, y1):
    """Area of the polygon (px, py)[:n] clipped to [x0, x1] × [y0, y1]."""
    ax = np.empty(16)
    ay = np.empty(16)
    bx = px.copy()
    by = py.copy()
    m = n
    for side in range(4):
        k = 0
        for i in range(m):
            j = (i + 1) % m
            xi, yi, xj, yj = bx[i], by[i], bx[j], by[j]
            if side == 0:
                di, dj = xi - x0, xj - x0
            elif side == 1:
                di, dj = x1 - xi, x1 - xj
            elif side == 2:
                di, dj = yi - y0, yj - y0
            else:
                di, dj = y1 - yi, y1 - yj
            if di >= 0.0:
                ax[k] = xi
                ay[k] = yi
                k += 1
            if (di >= 0.0) != (dj >= 0.0):
                t = di / (di - dj)
                ax[k] = xi + t * (xj - xi)
                ay[k] = yi + t * (yj - yi)
                k += 1
        m = k
        if m == 0:
            return 0.0
        for i in range(m):
            bx[i] = ax[i]
            by[i] = ay[i]
    s = 0.0
    for i in range(m):
        j = (i + 1) % m
        s += bx[i] * by[j] - bx[j] * by[i]
    return 0.5 * abs(s)


@njit(cache=True)
def _grid_sums(nodes, tri, values, xe, ye, num, den):
    nx = xe.shape[0] - 1
    ny = ye.shape[0] - 1
    dx = xe[1] - xe[0]
    dy = ye[1] - ye[0]
    px = np.empty(16)
    py = np.empty(16)
    nf = values.shape[1]
    for e in range(tri.shape[0]):
        for k in range(3):
            px[k] = nodes[tri[e, k], 0]
            py[k] = nodes[tri[e, k], 1]
        i0 = max(0, int(np.floor((min(px[0], px[1], px[2]) - xe[0]) / dx)))
        i1 = min(nx - 1, int(np.floor((max(px[0], px[1], px[2]) - xe[0]) / dx)))
        j0 = max(0, int(np.floor((min(py[0], py[1], py[2]) - ye[0]) / dy)))
        j1 = min(ny - 1, int(np.floor((max(py[0], py[1], py[2]) - ye[0]) / dy)))
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                a = _clip_area(px, py, 3, xe[i], xe[i + 1], ye[j], ye[j + 1])
                if a > 0.0:
                    den[j, i] += a
                    for f in range(nf):
                        num[f, j, i] += a * values[e, f]


def conservative_grid_average(nodes, triangles, fields: dict, x_edges, y_edges):
    """Area-weighted cell means of element ``fields`` ({name: (m,)}) on the grid
    with cell edges ``x_edges`` (nx+1,), ``y_edges`` (ny+1,) [m, uniform spacing].

    Returns ({name: (ny, nx)}, coverage (ny, nx) in [0, 1])."""
    xe = np.asarray(x_edges, np.float64)
    ye = np.asarray(y_edges, np.float64)
    names = list(fields)
    vals = (np.column_stack([np.asarray(fields[n], np.float64) for n in names]) if names
            else np.zeros((len(triangles), 0)))
    num = np.zeros((len(names), len(ye) - 1, len(xe) - 1))
    den = np.zeros((len(ye) - 1, len(xe) - 1))
    _grid_sums(np.ascontiguousarray(nodes, np.float64), np.ascontiguousarray(triangles, np.int64),
               np.ascontiguousarray(vals), xe, ye, num, den)
    cell = np.outer(np.diff(ye), np.diff(xe))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = {n: np.where(den > 0, num[k] / den, np.nan) for k, n in enumerate(names)}
    return out, den / cell


def gridded_dataset(model, resolution_m: float, crs="EPSG:3413", start_date="2000-01-01 00:00:00",
                    title: str = "lagice regular-grid output"):
    """xarray Dataset of the model's scalar element fields (field registry, those
    written to snapshots) averaged conservatively on a regular projected grid.

    The grid is a fixed lattice of the CRS plane (cell edges at whole multiples of
    ``resolution_m``) covering the mesh at that time: files written at different
    times (a mesh that moves) share the lattice, so they align into one time series
    (:func:`lagice.open_run`); cells a file does not reach are simply not covered."""
    import xarray as xr

    from ..fields import ELEMENT, FIELDS
    from .cf import CONVENTIONS, crs_variable, provenance, time_coordinate

    state = model.state
    lo = np.floor(state.mesh.nodes.min(axis=0) / resolution_m).astype(np.int64)
    hi = np.ceil(state.mesh.nodes.max(axis=0) / resolution_m).astype(np.int64)
    hi = np.maximum(hi, lo + 1)
    xe = resolution_m * np.arange(lo[0], hi[0] + 1)
    ye = resolution_m * np.arange(lo[1], hi[1] + 1)
    specs = [f for f in FIELDS.values() if f.location == ELEMENT and f.snapshot and not f.components
             and getattr(state, f.name, None) is not None]
    means, cov = conservative_grid_average(state.mesh.nodes, state.mesh.triangles,
                                           {f.name: getattr(state, f.name) for f in specs}, xe, ye)
    ds = xr.Dataset(coords={
        "x": ("x", resolution_m * (np.arange(lo[0], hi[0]) + 0.5), {
            "units": "m", "standard_name": "projection_x_coordinate", "axis": "X"}),
        "y": ("y", resolution_m * (np.arange(lo[1], hi[1]) + 0.5), {
            "units": "m", "standard_name": "projection_y_coordinate", "axis": "Y"}),
        "time": time_coordinate(model.clock.time_s, start_date),
    })
    gm = {}
    crs_var = crs_variable(crs)
    if crs_var is not None:
        ds["crs"] = crs_var
        gm = {"grid_mapping": "crs"}
    for f in specs:
        attrs = {"units": f.units, "long_name": f"{f.long_name}, conservative cell average", **gm,
                 "comment": "missing where no part of the cell is covered by the ice mesh (see coverage)"}
        if f.standard_name:
            attrs["standard_name"] = f.standard_name
        ds[f.name] = (("time", "y", "x"), means[f.name][None], attrs)
    ds["coverage"] = (("time", "y", "x"), cov[None], {"units": "1", "long_name":
                                                      "fraction of the cell covered by the mesh", **gm})
    ds.attrs.update(provenance(title, model.config, {"Conventions": CONVENTIONS, "step": int(model.clock.iteration)}))
    return ds


class GridWriter:
    """Writes ``grid_SSSSSSSS.nc``: element fields conservatively averaged on a
    regular grid of ``resolution_m`` [m] (see :func:`gridded_dataset`)."""

    def __init__(self, directory, resolution_m: float, crs="EPSG:3413",
                 start_date: str = "2000-01-01 00:00:00"):
        from pathlib import Path

        from ..errors import check_range

        check_range("output.grid_resolution_m", resolution_m, 0.0, None, low_open=True, unit="m")
        self.dir = Path(directory)
        self.resolution_m = float(resolution_m)
        self.crs = crs
        self.start_date = start_date

    def write(self, model):
        from .cf import write_netcdf_atomic

        self.dir.mkdir(parents=True, exist_ok=True)
        ds = gridded_dataset(model, self.resolution_m, self.crs, self.start_date)
        return write_netcdf_atomic(ds, self.dir / f"grid_{int(model.clock.iteration):08d}.nc")
