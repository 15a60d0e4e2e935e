"""Read a run folder back as time-indexed collections: :func:`open_run`.

    import lagice
    run = lagice.open_run("runs/winter_basin-latest")
    run.area_mean("damage").plot()              # a time series across remeshing

Snapshots live one per file because remeshing changes the mesh
(:mod:`lagice.io.snapshots`). :func:`open_run` groups them by mesh epoch (files
between two remesh events share their connectivity) into one xugrid dataset per
epoch with a ``time`` dimension, and concatenates the optional regular-grid files
into one xarray time series. Within an epoch the nodes still move with the ice:
the dataset's grid holds the node positions of the epoch's first snapshot and the
variables ``node_x(time, mesh_node)``, ``node_y(time, mesh_node)`` hold the
positions at every time. Everything is loaded eagerly (no dask needed): snapshot
files are small (a few MB for 10^4-10^5 elements).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import LagiceError

_GRID_VARS = ("mesh", "mesh_node_x", "mesh_node_y", "mesh_face_nodes", "crs")


class RunOutputs:
    """The outputs of one run folder (see the module docstring).

    Attributes:
        path: the run folder.
        index: snapshot entries (``file``, ``time_s``, ``step``, ``mesh_epoch``), in time order.
        config: the scene configuration the run was made with (dict).
        summary: ``summary.json`` (dict) or None while the run has not ended.
    """

    def __init__(self, path):
        from .snapshots import read_index, snapshot_dir

        self.snapshot_dir = snapshot_dir(path)
        self.path = self.snapshot_dir.parent if self.snapshot_dir.name == "snapshots" else self.snapshot_dir
        self.index = read_index(self.snapshot_dir)
        if not self.index:
            raise LagiceError(f"{self.path}: the run has no snapshots yet")
        s = self.path / "summary.json"
        self.summary = json.loads(s.read_text()) if s.exists() else None
        self._epochs = None
        self._first = self._open(0)
        raw = self._first.attrs.get("lagice_config")
        self.config = json.loads(raw) if raw else {}

    def __repr__(self):
        return (f"<lagice run {self.path}: {len(self.index)} snapshots, t = {self.index[0]['time_s']:g}.."
                f"{self.index[-1]['time_s']:g} s, {len(self.epoch_numbers)} mesh epoch(s)>")

    def __len__(self):
        return len(self.index)

    # -- single snapshots --------------------------------------------------------
    def _open(self, i: int):
        import xarray as xr

        return xr.load_dataset(self.snapshot_dir / self.index[i]["file"])

    @property
    def time_s(self) -> np.ndarray:
        """Snapshot times [s since run.start_date]."""
        return np.array([e["time_s"] for e in self.index])

    @property
    def times(self) -> np.ndarray:
        """Snapshot dates (datetime64), from ``run.start_date``."""
        start = np.datetime64(self._first["time"].values[0]) - np.timedelta64(
            int(round(self.index[0]["time_s"] * 1e9)), "ns")
        return start + (self.time_s * 1e9).round().astype("timedelta64[ns]")

    def snapshot(self, i: int):
        """Snapshot ``i`` (negative counts from the end) as an xugrid dataset."""
        import xugrid as xu

        return xu.UgridDataset(self._open(range(len(self.index))[i]))

    # -- epochs --------------------------------------------------------------------
    @property
    def epoch_numbers(self) -> list[int]:
        return sorted({int(e["mesh_epoch"]) for e in self.index})

    @property
    def epochs(self) -> list:
        """One xugrid dataset per mesh epoch, with a ``time`` dimension; node positions
        per time in ``node_x``/``node_y`` (the grid holds the epoch's first ones)."""
        if self._epochs is None:
            self._epochs = [self._epoch(k) for k in self.epoch_numbers]
        return self._epochs

    def _epoch(self, k: int):
        import xarray as xr
        import xugrid as xu

        idx = [i for i, e in enumerate(self.index) if int(e["mesh_epoch"]) == k]
        parts, grid = [], None
        for i in idx:
            ds = self._open(i)
            if grid is None:
                grid = ds[[v for v in _GRID_VARS if v in ds]]
            for name, src in (("node_x", "mesh_node_x"), ("node_y", "mesh_node_y")):
                ds[name] = (("time", "mesh_node"), ds[src].values[None],
                            {**ds[src].attrs, "long_name": f"{src[-1]} position of the node at this time"})
            parts.append(ds.drop_vars([v for v in _GRID_VARS if v in ds]))
        cat = xr.concat(parts, dim="time", data_vars="minimal", coords="minimal", compat="override",
                        join="outer")
        merged = xr.merge([grid, cat], compat="override", combine_attrs="override")
        merged.attrs["mesh_epoch"] = k
        return xu.UgridDataset(merged)

    # -- time series ------------------------------------------------------------------
    def area_mean(self, name: str):
        """Area-weighted mean of the element field ``name`` (node fields: plain mean)
        at every snapshot time, across mesh epochs (each snapshot weighted by its own
        element areas), as an xarray DataArray over ``time``."""
        import xarray as xr

        vals = []
        for i in range(len(self.index)):
            ds = self._first if i == 0 else self._open(i)
            if name not in ds:
                vals.append(np.nan)
                continue
            v = ds[name].values[0]
            if ds[name].attrs.get("location") == "face":
                xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
                t = ds["mesh_face_nodes"].values.astype(np.int64)
                a, b, c = xy[t[:, 0]], xy[t[:, 1]], xy[t[:, 2]]
                area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
                                    - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1]))
                vals.append(float(np.sum(v * area) / np.sum(area)))
            else:
                vals.append(float(np.mean(v)))
        attrs = dict(self._first[name].attrs) if name in self._first else {}
        attrs = {k: v for k, v in attrs.items() if k in ("units", "standard_name", "long_name")}
        attrs["long_name"] = f"area mean of {attrs.get('long_name', name)}"
        attrs.pop("standard_name", None)
        return xr.DataArray(np.array(vals), coords={"time": self.times}, dims="time", name=name, attrs=attrs)

    @property
    def grid(self):
        """The regular-grid files (``output.grid_resolution_m``) as one xarray time series
        on their common lattice (``coverage`` 0 where a file did not reach), or None."""
        import xarray as xr

        files = sorted(self.snapshot_dir.glob("grid_*.nc"))
        if not files:
            return None
        parts = [xr.load_dataset(f) for f in files]
        ds = xr.concat(parts, dim="time", data_vars="minimal", coords="minimal", compat="override", join="outer",
                       combine_attrs="override")
        ds["coverage"] = ds["coverage"].fillna(0.0)
        return ds

    @property
    def timeseries(self):
        """``timeseries.nc`` (scalar diagnostics) as an xarray Dataset, or None."""
        import xarray as xr

        p = self.path / "timeseries.nc"
        return xr.load_dataset(p) if p.exists() else None

    @property
    def drifters(self):
        """``drifters.nc`` (CF trajectories) as an xarray Dataset, or None."""
        import xarray as xr

        p = self.path / "drifters.nc"
        return xr.load_dataset(p) if p.exists() else None


def open_run(path) -> RunOutputs:
    """The outputs of the run folder ``path`` (or its snapshot folder, or a
    ``runs/SCENE-latest`` link): snapshots by mesh epoch (xugrid), the regular-grid
    time series, time series, drifters, configuration and summary."""
    p = Path(path)
    if not p.exists():
        raise LagiceError(f"run folder {p} does not exist")
    return RunOutputs(p)
