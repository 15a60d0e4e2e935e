"""Drifter trajectories as a CF-1.8 discrete-sampling-geometry file
(``featureType = "trajectory"``, multidimensional array representation, CF §9 and
appendix H.4.1): ``drifters.nc`` in the run folder.

Dimensions ``trajectory`` (one per drifter) and ``obs`` (one per outer step, the
positions the model records every step). Variables: ``trajectory``
(``cf_role = "trajectory_id"``), ``time``, ``lon``, ``lat`` (from the scene CRS),
``x``, ``y`` (projected metres, with the ``crs`` grid mapping) and ``lost`` (1 once
a drifter has left the mesh through an open boundary: it stops there). The file
is rewritten atomically on the snapshot schedule and at the end of the run.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .cf import CONVENTIONS, crs_variable, provenance, write_netcdf_atomic


def drifter_dataset(model, crs="EPSG:3413", start_date: str = "2000-01-01 00:00:00",
                    title: str = "lagice drifter trajectories"):
    """The drifters of ``model`` as an xarray Dataset (CF trajectory DSG)."""
    import xarray as xr

    dr = model.drifters
    track = np.array(dr.track)                          # (n_obs, k, 2)
    times = np.asarray(dr.times_s(), np.float64)        # (n_obs,)
    k = track.shape[1]
    x = np.ascontiguousarray(track[:, :, 0].T)          # (k, n_obs)
    y = np.ascontiguousarray(track[:, :, 1].T)
    ds = xr.Dataset()
    ds["trajectory"] = ("trajectory", np.arange(k, dtype=np.int32),
                        {"cf_role": "trajectory_id", "long_name": "drifter number"})
    ds["time"] = (("trajectory", "obs"), np.broadcast_to(times, (k, times.size)).copy(),
                  {"units": f"seconds since {start_date}", "standard_name": "time", "calendar": "standard",
                   "axis": "T", "long_name": "time of the position"})
    gm = {}
    if crs is not None:
        from ..crs import lonlat

        lon, lat = lonlat(crs, x.ravel(), y.ravel())
        ds["lon"] = (("trajectory", "obs"), lon.reshape(x.shape),
                     {"units": "degrees_east", "standard_name": "longitude", "axis": "X"})
        ds["lat"] = (("trajectory", "obs"), lat.reshape(x.shape),
                     {"units": "degrees_north", "standard_name": "latitude", "axis": "Y"})
        ds["crs"] = crs_variable(crs)
        gm = {"grid_mapping": "crs"}
    coords = "time lat lon" if crs is not None else "time"
    ds["x"] = (("trajectory", "obs"), x, {"units": "m", "standard_name": "projection_x_coordinate",
                                          "long_name": "drifter x position in the model plane",
                                          "coordinates": coords, **gm})
    ds["y"] = (("trajectory", "obs"), y, {"units": "m", "standard_name": "projection_y_coordinate",
                                          "long_name": "drifter y position in the model plane",
                                          "coordinates": coords, **gm})
    ds["lost"] = ("trajectory", dr.lost.astype(np.int8),
                  {"long_name": "drifter left the mesh through an open boundary (it stops there)",
                   "flag_values": np.array([0, 1], np.int8), "flag_meanings": "on_ice lost"})
    ds.attrs.update(provenance(title, model.config, {"Conventions": CONVENTIONS, "featureType": "trajectory"}))
    return ds


class DrifterWriter:
    """Writes ``path`` (the drifter trajectory file) atomically."""

    def __init__(self, path, crs="EPSG:3413", start_date: str = "2000-01-01 00:00:00"):
        self.path = Path(path)
        self.crs = crs
        self.start_date = start_date

    def write(self, model) -> Path:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        return write_netcdf_atomic(drifter_dataset(model, self.crs, self.start_date), self.path)


def read_trajectories(path) -> list[np.ndarray]:
    """The trajectories of a drifter file: one ``(n_obs, 2)`` array [m] per drifter."""
    import xarray as xr

    with xr.open_dataset(path, decode_times=False) as ds:
        x, y = ds["x"].values, ds["y"].values
    return [np.column_stack([x[k], y[k]]) for k in range(x.shape[0])]
