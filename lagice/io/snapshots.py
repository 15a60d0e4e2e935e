"""Snapshot output: one UGRID-1.0 / CF netCDF file per snapshot.

Remeshing changes the mesh, so a time series cannot live on one fixed mesh
dimension. Each snapshot file ``snapshot_SSSSSS.nc`` holds its own mesh
(UGRID topology ``mesh``) and the element/node fields at one time; the
attribute ``mesh_epoch`` counts remesh events, so files with equal epochs
share the same mesh. ``index.json`` lists every snapshot (file, time, step,
mesh epoch). With a grid resolution, ``grid_SSSSSSSS.nc`` holds the
element fields conservatively averaged on a regular projected grid
(:mod:`lagice.io.gridded`); with ``vtu`` a ``.vtu`` file per snapshot is
written for ParaView. Open one with ``xugrid.open_dataset`` or ``xarray.open_dataset``;
the files of one epoch concatenate with ``xarray.open_mfdataset(...,
combine="nested", concat_dim="time")``.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import xarray as xr

from ..deformation import invariants
from .ugrid import mesh_dataset

FIELD_ATTRS = {
    "thickness": ("sea_ice_thickness", "m", "ice volume per unit area (effective thickness)"),
    "concentration": ("sea_ice_area_fraction", "1", "ice concentration"),
    "damage": (None, "1", "damage (0 undamaged, 1 fully damaged)"),
    "cohesion": (None, "Pa", "cohesion"),
    "snow": ("surface_snow_thickness", "m", "snow volume per unit area"),
}


def _crs_var(crs_epsg: int | None):
    if crs_epsg is None:
        return None
    try:
        import pyproj

        crs = pyproj.CRS.from_epsg(crs_epsg)
        attrs = crs.to_cf()
        attrs["crs_wkt"] = crs.to_wkt()
        return xr.DataArray(np.int32(0), attrs=attrs)
    except Exception:  # noqa: BLE001 - pyproj missing data: keep the EPSG code
        return xr.DataArray(np.int32(0), attrs={"epsg_code": f"EPSG:{crs_epsg}"})


def snapshot_dataset(state, strain_rate=None, crs_epsg: int | None = 3413, extra: dict | None = None,
                     start_date: str = "2000-01-01 00:00:00"):
    """The snapshot of ``state`` as an xarray Dataset (UGRID + CF attributes)."""
    ds = mesh_dataset(state.mesh)
    grid_mapping = {}
    crs = _crs_var(crs_epsg)
    if crs is not None:
        ds["crs"] = crs
        grid_mapping = {"grid_mapping": "crs"}
        ds["mesh_node_x"].attrs.update(grid_mapping)
        ds["mesh_node_y"].attrs.update(grid_mapping)
    face = {"mesh": "mesh", "location": "face", **grid_mapping}
    node = {"mesh": "mesh", "location": "node", **grid_mapping}
    ds["time"] = ("time", np.array([state.time_s]), {"units": f"seconds since {start_date}",
                                                     "standard_name": "time", "calendar": "standard"})
    for name, (std, units, long) in FIELD_ATTRS.items():
        val = getattr(state, name, None)
        if val is None:
            continue
        attrs = {"units": units, "long_name": long, **face}
        if std:
            attrs["standard_name"] = std
        ds[name] = (("time", "mesh_face"), val[None, :], attrs)
    ds["stress"] = (("time", "mesh_face", "stress_component"), state.stress[None],
                    {"units": "Pa", "long_name": "depth-averaged internal stress (xx, yy, xy), tension positive",
                     **face})
    ds["stress_component"] = ("stress_component", np.array(["xx", "yy", "xy"]))
    ds["velocity_x"] = (("time", "mesh_node"), state.velocity[None, :, 0],
                        {"units": "m s-1", "standard_name": "sea_ice_x_velocity", **node})
    ds["velocity_y"] = (("time", "mesh_node"), state.velocity[None, :, 1],
                        {"units": "m s-1", "standard_name": "sea_ice_y_velocity", **node})
    if getattr(state, "node_id", None) is not None:
        ds["node_id"] = ("mesh_node", np.asarray(state.node_id, np.int64),
                         {"long_name": "persistent node identifier (kept through remeshing)", "units": "1",
                          "mesh": "mesh", "location": "node"})
    if strain_rate is not None:
        div, shear, tot = invariants(strain_rate)
        for name, val, long in (("divergence_rate", div, "divergence of ice velocity"),
                                ("shear_rate", shear, "maximum shear rate"),
                                ("total_deformation_rate", tot, "total deformation rate sqrt(div^2+shear^2)")):
            ds[name] = (("time", "mesh_face"), val[None], {"units": "s-1", "long_name": long, **face})
    ds.attrs.update({"Conventions": "CF-1.8 UGRID-1.0", "step": int(state.step),
                     "mesh_epoch": int(state.counters.get("mesh_epoch", 0)), **(extra or {})})
    return ds


class SnapshotWriter:
    """Writes snapshots and keeps ``index.json`` up to date (atomically)."""

    def __init__(self, directory, crs_epsg: int | None = 3413, vtu: bool = False,
                 start_date: str = "2000-01-01 00:00:00", grid_resolution_m: float | None = None):
        self.dir = Path(directory)
        self.grid_resolution_m = grid_resolution_m
        self.start_date = start_date
        self.crs_epsg = crs_epsg
        self.vtu = vtu

    def write(self, state, strain_rate=None, extra=None) -> Path:
        self.dir.mkdir(parents=True, exist_ok=True)
        path = self.dir / f"snapshot_{state.step:08d}.nc"
        ds = snapshot_dataset(state, strain_rate, self.crs_epsg, extra, self.start_date)
        tmp = path.with_suffix(".nc.tmp")
        # no fill values: every value written is a model value
        ds.to_netcdf(tmp, encoding={v: {"_FillValue": None} for v in ds.variables
                                    if ds[v].dtype.kind == "f"})
        os.replace(tmp, path)
        if self.vtu:
            from ..mesh import write_mesh
            cd = {k: getattr(state, k) for k in ("thickness", "concentration", "damage")}
            write_mesh(path.with_suffix(".vtu"), state.mesh, cell_data=cd,
                       point_data={"velocity": np.column_stack([state.velocity, np.zeros(len(state.velocity))])})
        if self.grid_resolution_m:
            from .gridded import gridded_dataset
            gds = gridded_dataset(state, self.grid_resolution_m, self.crs_epsg, self.start_date)
            gpath = self.dir / f"grid_{state.step:08d}.nc"
            gds.to_netcdf(gpath.with_suffix(".nc.tmp"))
            os.replace(gpath.with_suffix(".nc.tmp"), gpath)
        self._index_add({"file": path.name, "time_s": state.time_s, "step": int(state.step),
                         "mesh_epoch": int(state.counters.get("mesh_epoch", 0))})
        return path

    def _index_add(self, entry):
        idx_path = self.dir / "index.json"
        entries = json.loads(idx_path.read_text()) if idx_path.exists() else []
        entries = [e for e in entries if e["step"] < entry["step"]]  # a resumed run rewrites later ones
        entries.append(entry)
        tmp = idx_path.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(entries, indent=1))
        os.replace(tmp, idx_path)


def snapshot_dir(path) -> Path:
    """The snapshot folder of a run directory or the folder itself (holds ``index.json``)."""
    from ..errors import LagiceError

    p = Path(path)
    if (p / "index.json").exists():
        return p
    if (p / "snapshots" / "index.json").exists():
        return p / "snapshots"
    raise LagiceError(f"{p} is not a run directory or snapshot folder (no index.json)")


def read_index(path) -> list[dict]:
    """Entries of ``index.json`` (file, time_s, step, mesh_epoch), in time order."""
    d = snapshot_dir(path)
    return sorted(json.loads((d / "index.json").read_text()), key=lambda e: e["time_s"])


def load_window(path, start_s: float, end_s: float) -> dict:
    """Node positions at the snapshots nearest ``start_s`` and ``end_s`` (s), for
    Lagrangian deformation over the window (``lagice.diagnostics``).

    Returns ``{"xy0", "xy1" (n, 2) m, "triangles" (m, 3), "dt_s", "start_s", "end_s",
    "fixed_mesh", "velocity0", "velocity1" (n, 2) m s-1, "n_elements_lost",
    "kept_elements" (indices into the first mesh's triangles), "start_mesh": (nodes,
    triangles) of the first snapshot, "remesh_events", "datasets": (first, last)}``.
    Masks that depend on the domain boundary (coast distance) should be computed
    on ``start_mesh`` and indexed with ``kept_elements``: the elements left out
    by remeshing open holes that are not coasts.

    If remeshing happened inside the window (the mesh epochs differ), nodes are
    followed by their persistent ``node_id`` (:class:`~lagice.state.IceState`):
    the result keeps the elements of the first mesh whose three nodes still
    exist at the end (those outside every remeshed patch), renumbered, and
    ``n_elements_lost`` counts the others. Files without ``node_id`` cannot be
    matched: :class:`~lagice.errors.LagiceError` names the epochs.
    ``fixed_mesh`` is True when no node moved at all (a Eulerian run): the
    caller should then use the velocities.
    """
    from ..errors import LagiceError

    d = snapshot_dir(path)
    idx = read_index(d)
    times = np.array([e["time_s"] for e in idx])
    e0 = idx[int(np.argmin(np.abs(times - start_s)))]
    e1 = idx[int(np.argmin(np.abs(times - end_s)))]
    if not e1["time_s"] > e0["time_s"]:
        raise LagiceError(f"{d}: no window between {start_s:g} s and {end_s:g} s "
                          f"(nearest snapshots at {e0['time_s']:g} s and {e1['time_s']:g} s)")
    ds0 = xr.load_dataset(d / e0["file"], decode_times=False)
    ds1 = xr.load_dataset(d / e1["file"], decode_times=False)

    def nodes_vel(ds):
        return (np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values]),
                np.column_stack([ds["velocity_x"].values[0], ds["velocity_y"].values[0]]))

    xy0, v0 = nodes_vel(ds0)
    xy1, v1 = nodes_vel(ds1)
    tri = ds0["mesh_face_nodes"].values.astype(np.int64)
    start_mesh = (xy0, tri)
    kept = np.arange(tri.shape[0])
    lost = 0
    if e0["mesh_epoch"] != e1["mesh_epoch"]:
        if "node_id" not in ds0 or "node_id" not in ds1:
            raise LagiceError(f"{d}: the window {e0['time_s']:g}-{e1['time_s']:g} s spans a remesh "
                              f"(mesh epochs {e0['mesh_epoch']} and {e1['mesh_epoch']}) and the files have no "
                              f"node_id to follow nodes across it; choose a window inside one epoch")
        id0, id1 = ds0["node_id"].values, ds1["node_id"].values
        order = np.argsort(id1)
        pos = np.searchsorted(id1[order], id0)
        pos = np.minimum(pos, id1.size - 1)
        found = id1[order][pos] == id0
        at_end = np.where(found, order[pos], -1)          # end index of each start node, -1 if gone
        keep_el = np.all(found[tri], axis=1)
        lost = int(tri.shape[0] - keep_el.sum())
        kept = np.flatnonzero(keep_el)
        tri = tri[keep_el]
        used = np.unique(tri)
        renum = np.full(xy0.shape[0], -1, np.int64)
        renum[used] = np.arange(used.size)
        tri = renum[tri]
        xy0, v0 = xy0[used], v0[used]
        xy1, v1 = xy1[at_end[used]], v1[at_end[used]]
    elif xy0.shape != xy1.shape:
        raise LagiceError(f"{d}: snapshots {e0['file']} and {e1['file']} share mesh epoch {e0['mesh_epoch']} "
                          f"but have {xy0.shape[0]} and {xy1.shape[0]} nodes")
    return {"xy0": xy0, "xy1": xy1, "triangles": tri,
            "dt_s": float(e1["time_s"] - e0["time_s"]), "start_s": float(e0["time_s"]),
            "end_s": float(e1["time_s"]), "fixed_mesh": bool(np.array_equal(xy0, xy1)),
            "velocity0": v0, "velocity1": v1, "n_elements_lost": lost, "kept_elements": kept,
            "start_mesh": start_mesh,
            "remesh_events": int(e1["mesh_epoch"] - e0["mesh_epoch"]), "datasets": (ds0, ds1)}
