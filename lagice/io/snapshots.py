"""Snapshot output: one UGRID-1.0 / CF netCDF file per snapshot.

Remeshing changes the mesh, so a time series cannot live on one fixed mesh
dimension. Each snapshot file ``snapshot_SSSSSSSS.nc`` holds its own mesh
(UGRID topology ``mesh``) and the state fields the field registry marks for
snapshots (:mod:`lagice.fields`), plus the diagnostics every snapshot carries:
the transport velocity (the velocity that moved the nodes over the last step)
and the deformation rates of that velocity. The attribute ``mesh_epoch`` counts
remesh events, so files with equal epochs share the same mesh. ``index.json``
lists every snapshot (file, time, step, mesh epoch). Open a run's snapshots with
:func:`lagice.open_run` (docs/output_and_restart.md).
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import xarray as xr

from ..deformation import invariants
from ..fields import DIAGNOSTICS, FIELDS, cf_attrs
from .cf import CONVENTIONS_UGRID, atomic_write_errors, crs_variable, provenance, time_coordinate, write_netcdf_atomic
from .ugrid import mesh_dataset


def snapshot_dataset(model, crs="EPSG:3413", start_date: str = "2000-01-01 00:00:00",
                     title: str = "lagice snapshot", extra: dict | None = None):
    """The snapshot of ``model`` (state, clock, transport velocity, deformation
    rates) as an xarray Dataset with UGRID and CF attributes."""
    state = model.state
    ds = mesh_dataset(state.mesh)
    gm = None
    crs_var = crs_variable(crs)
    if crs_var is not None:
        ds["crs"] = crs_var
        gm = "crs"
        ds["mesh_node_x"].attrs["grid_mapping"] = gm
        ds["mesh_node_y"].attrs["grid_mapping"] = gm
    ds["time"] = time_coordinate(model.clock.time_s, start_date)
    dims = {"node": "mesh_node", "element": "mesh_face"}
    for spec in FIELDS.values():
        val = getattr(state, spec.name, None)
        if not spec.snapshot or val is None:
            continue
        dim = dims[spec.location]
        if spec.name == "node_id":
            if val.size and val.max() > np.iinfo(np.int32).max:
                raise OverflowError("node_id exceeds the int32 range of the snapshot format")
            attrs = {"long_name": spec.long_name, "units": "1", "mesh": "mesh", "location": "node"}
            ds["node_id"] = (dim, val.astype(np.int32), attrs)
            continue
        if spec.components:
            for k, comp in enumerate(spec.components):
                attrs = cf_attrs(spec, gm)
                attrs["long_name"] = f"{spec.long_name}, {comp} component"
                ds[f"{spec.name}_{comp}"] = (("time", dim), val[None, :, k], attrs)
        else:
            ds[spec.name] = (("time", dim), val[None, :], cf_attrs(spec, gm))
    vel = model.transport_velocity
    for k, name in enumerate(("velocity_x", "velocity_y")):
        ds[name] = (("time", "mesh_node"), vel[None, :, k], cf_attrs(DIAGNOSTICS[name], gm))
    eps = model.strain_rate
    if eps is not None:
        div, shear, tot = invariants(eps)
        for name, val in (("divergence_rate", div), ("shear_rate", shear), ("total_deformation_rate", tot)):
            ds[name] = (("time", "mesh_face"), val[None], cf_attrs(DIAGNOSTICS[name], gm))
    since = ({"strain_accumulated_since_s": float(state.counters["strain_accumulated_since_s"])}
             if state.strain_accumulated is not None and "strain_accumulated_since_s" in state.counters else {})
    ds.attrs.update(provenance(title, model.config, {
        "Conventions": CONVENTIONS_UGRID, "step": int(model.clock.iteration),
        "mesh_epoch": int(state.counters.get("mesh_epoch", 0)), **since, **(extra or {})}))
    return ds


class SnapshotWriter:
    """Writes snapshots of a model and keeps ``index.json`` up to date (atomically)."""

    def __init__(self, directory, crs="EPSG:3413", start_date: str = "2000-01-01 00:00:00",
                 title: str = "lagice snapshot", extra: dict | None = None):
        self.dir = Path(directory)
        self.start_date = start_date
        self.crs = crs
        self.title = title
        self.extra = dict(extra or {})

    def write(self, model) -> Path:
        self.dir.mkdir(parents=True, exist_ok=True)
        step = int(model.clock.iteration)
        path = self.dir / f"snapshot_{step:08d}.nc"
        ds = snapshot_dataset(model, self.crs, self.start_date, self.title, self.extra)
        write_netcdf_atomic(ds, path)
        self._index_add({"file": path.name, "time_s": model.clock.time_s, "step": step,
                         "mesh_epoch": int(model.state.counters.get("mesh_epoch", 0))})
        return path

    def _index_add(self, entry):
        idx_path = self.dir / "index.json"
        entries = json.loads(idx_path.read_text()) if idx_path.exists() else []
        entries = [e for e in entries if e["step"] < entry["step"]]  # a resumed run rewrites later ones
        entries.append(entry)
        tmp = idx_path.with_suffix(".json.tmp")
        with atomic_write_errors(idx_path, tmp):
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
    triangles) of the first snapshot, "start_nodes_at_end" (n0, 2) m (the end position of
    each node of the first mesh, NaN where remeshing replaced it), "remesh_events",
    "datasets": (first, last)}``.
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
    start_at_end = xy1  # the same nodes when the mesh did not change
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
        start_at_end = np.where(found[:, None], xy1[at_end], np.nan)
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
            "start_mesh": start_mesh, "start_nodes_at_end": start_at_end,
            "remesh_events": int(e1["mesh_epoch"] - e0["mesh_epoch"]), "datasets": (ds0, ds1)}
