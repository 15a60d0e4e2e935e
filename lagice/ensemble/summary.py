"""Ensemble outputs: the summary netCDF (``member`` dimension), the regular-grid
outputs combined along ``member`` (lazy, dask), and the spread figure."""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import LagiceError
from .member import DIAG_KEYS

#: variables of the summary: name -> (record path, units, long name)
SCALARS = {
    "wall_s": (("wall_s",), "s", "wall time of the member task (build, run, diagnostics)"),
    "cpu_s": (("cpu_s",), "s", "CPU time of the worker process during the member task (all its threads); "
              + "well below wall_s when the member waited for a core"),
    "loop_wall_s": (("summary", "wall_s"), "s", "wall time of the time loop (this attempt)"),
    "time_s": (("summary", "time_s"), "s", "simulated time at the end"),
    "steps": (("summary", "steps"), "1", "time steps at the end"),
    "remesh_count": (("summary", "remesh_count"), "1", "remesh events"),
    "volume_initial_m3": (("summary", "volume_budget", "initial_m3"), "m3", "initial ice volume"),
    "volume_final_m3": (("summary", "volume_budget", "current_m3"), "m3", "final ice volume"),
    "volume_thermodynamic_m3": (("summary", "volume_budget", "thermodynamic_m3"), "m3",
                                "ice volume change by thermodynamics"),
    "volume_outflow_m3": (("summary", "volume_budget", "outflow_m3"), "m3", "ice volume lost through open boundaries"),
    "volume_residual_m3": (("summary", "volume_budget", "residual_m3"), "m3",
                           "volume budget residual V - V0 - thermodynamic + outflow"),
    "volume_relative_residual": (("summary", "volume_budget", "relative_residual"), "1",
                                 "volume budget residual / initial volume"),
    "numba_threads": (("numba_threads",), "1", "numba threads of the worker that ran the member"),
}
DIAG_ATTRS = {
    "beta_space": ("1", "beta of <total deformation rate> ~ L^-beta (spatial coarse-graining)"),
    "beta_space_r2": ("1", "R2 of the log-log fit of beta"),
    "pdf_tail_exponent_shear": ("1", "maximum-likelihood tail exponent of the shear-rate PDF"),
    "pdf_tail_exponent_divergence": ("1", "maximum-likelihood tail exponent of the |divergence|-rate PDF"),
    "localisation_half_shear_area_fraction": ("1", "area fraction of the highest-shear elements holding half "
                                                  + "of the shear"),
    "shear_divergence_r2": ("1", "squared correlation of |divergence| and shear rates over elements"),
    "mean_total_s": ("s-1", "mean element total deformation rate"),
    "mean_shear_s": ("s-1", "mean element shear rate"),
    "mean_abs_divergence_s": ("s-1", "mean element |divergence| rate"),
}


def _get(rec, path):
    node = rec
    for p in path:
        if not isinstance(node, dict) or p not in node or node[p] is None:
            return math.nan
        node = node[p]
    return node


def summary_dataset(records: list[dict], spec_info: dict) -> xr.Dataset:
    """The ensemble summary: one entry per member along ``member`` (string ids).

    ``records``: member records in member order (``done.json``/``failed.json``
    contents, or ``{"member": id, "status": "not_run"}``)."""
    ids = [r["member"] for r in records]
    ds = xr.Dataset(coords={"member": ("member", np.array(ids, dtype=object),
                                       {"long_name": "ensemble member id (folder members/<id>)"})})
    ds["status"] = ("member", np.array([r.get("status", "not_run") for r in records], dtype=object),
                    {"long_name": "member status: done, failed, stopped (a clean stop with a checkpoint: "
                                 "re-running resumes it) or not_run"})
    ds["error"] = ("member", np.array([r.get("error") or "" for r in records], dtype=object),
                   {"long_name": "error of a failed member (type: message), why a member stopped or did not "
                                 "run, empty otherwise"})
    ds["resumed_from"] = ("member", np.array([r.get("resumed_from") or "" for r in records], dtype=object),
                          {"long_name": "checkpoint the member's last attempt resumed from, empty if none"})
    for name, (path, units, long) in SCALARS.items():
        ds[name] = ("member", np.array([float(_get(r, path)) for r in records]), {"units": units, "long_name": long})
    diag = [r.get("diagnostics") or {} for r in records]
    for k in DIAG_KEYS:
        units, long = DIAG_ATTRS[k]
        ds[k] = ("member", np.array([float(d.get(k, math.nan)) for d in diag]),
                 {"units": units, "long_name": f"{long}; median over the analysis windows",
                  "comment": "NaN where diag_status is not 'ok' (see diag_status)"})
    ds["diag_status"] = ("member", np.array([d.get("diag_status", "not_computed: member not done") for d in diag],
                                            dtype=object),
                         {"long_name": "deformation statistics status: ok, or why they are NaN"})
    ds["diag_window_s"] = ("member", np.array([float(d.get("diag_window_s", math.nan)) for d in diag]),
                           {"units": "s", "long_name": "length of each analysis window"})
    ds["diag_n_windows"] = ("member", np.array([int(d.get("diag_n_windows", 0)) for d in diag], np.int32),
                            {"units": "1", "long_name": "number of analysis windows"})
    ds["diag_n_folded"] = ("member", np.array([int(d.get("diag_n_folded", 0)) for d in diag], np.int32),
                           {"units": "1", "long_name": "elements inside the coast buffer left out of the statistics "
                                                       "because their mid-window geometry is inverted, summed over "
                                                       "the analysis windows (as lagice diagnose does)"})
    ds["overrides"] = ("member", np.array([json.dumps(r.get("overrides", {}), sort_keys=True, default=str)
                                           for r in records], dtype=object),
                       {"long_name": "the member's own overrides (JSON, dotted keys)"})
    keys = []
    for r in records:
        for k in r.get("overrides", {}):
            if k not in keys:
                keys.append(k)
    for k in keys:  # the value each member ran with (its override, else the base/common value)
        vals = [r.get("values", r.get("overrides", {})).get(k) for r in records]
        var = "set_" + k.replace(".", "_")
        attrs = {"long_name": f"value of {k} in each member (overridden in some members)", "override_key": k}
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
            ds[var] = ("member", np.array(vals, np.float64), attrs)
        else:
            ds[var] = ("member", np.array([json.dumps(v) if not isinstance(v, str) else v for v in vals],
                                          dtype=object), attrs)
    n_done = sum(r.get("status") == "done" for r in records)
    ds.attrs.update({
        "title": f"lagice ensemble {spec_info.get('name')}: member summary",
        "Conventions": "CF-1.8",
        "ensemble_name": spec_info.get("name", ""),
        "ensemble_base": spec_info.get("base") or "",
        "ensemble_parent_checkpoint": spec_info.get("branch_from") or "",
        "ensemble_parent_checkpoint_sha256": spec_info.get("branch_sha256") or "",
        "ensemble_common_overrides": json.dumps(spec_info.get("common", {}), sort_keys=True, default=str),
        "ensemble_analysis": json.dumps(spec_info.get("analysis", {}), default=str),
        "members_done": n_done, "members_failed": sum(r.get("status") == "failed" for r in records),
        "members_total": len(records), "lagice_version": spec_info.get("lagice_version", ""),
        "history": f"{spec_info.get('created', '')} lagice ensemble {spec_info.get('source', '')}",
    })
    return ds


def write_summary(ds: xr.Dataset, path: Path) -> Path:
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    enc = {v: {"_FillValue": None} for v in ds.variables if ds[v].dtype.kind == "f"}
    ds.to_netcdf(tmp, encoding=enc)
    os.replace(tmp, path)
    return path


def open_summary(out_dir) -> xr.Dataset:
    """The ensemble summary ``DIR/ensemble_summary.nc`` (loaded)."""
    p = Path(out_dir) / "ensemble_summary.nc"
    if not p.exists():
        raise LagiceError(f"{out_dir} has no ensemble_summary.nc (run `lagice ensemble SPEC --out {out_dir}`)")
    return xr.load_dataset(p)


# -- combined regular-grid outputs -------------------------------------------------------
def member_ids(out_dir) -> list[str]:
    """Member ids in spec order (``DIR/ensemble.json``)."""
    p = Path(out_dir) / "ensemble.json"
    if not p.exists():
        raise LagiceError(f"{out_dir} is not an ensemble folder (no ensemble.json)")
    return list(json.loads(p.read_text())["members"])


def open_grids(out_dir, members=None, include_failed: bool = False, chunks=None) -> xr.Dataset:
    """The regular-grid outputs of the members (``output.grid_resolution_m``), combined
    lazily (dask) along a ``member`` dimension: variables (member, time, y, x).

    By default only finished members (``done.json``) are included. Members must
    share the grid and the output times; otherwise a :class:`LagiceError` names
    the first member that differs."""
    out_dir = Path(out_dir)
    ids = members or member_ids(out_dir)
    if not include_failed:
        ids = [m for m in ids if (out_dir / "members" / m / "done.json").exists()]
    if not ids:
        raise LagiceError(f"{out_dir}: no finished member to combine")
    dsets = []
    for m in ids:
        files = sorted((out_dir / "members" / m / "snapshots").glob("grid_*.nc"))
        if not files:
            raise LagiceError(f"{out_dir}: member {m!r} has no regular-grid output (grid_*.nc); set "
                              "output.grid_resolution_m in the base scene or the spec's [set]")
        try:
            ds = xr.open_mfdataset(files, combine="nested", concat_dim="time", data_vars="minimal",
                                   coords="minimal", compat="override", join="exact",
                                   chunks=chunks if chunks is not None else {})
        except ValueError as exc:
            raise LagiceError(f"{out_dir}: member {m!r}: its grid files do not share x/y coordinates "
                              f"(the mesh bounding box moved?): {exc}") from exc
        dsets.append(ds)
    fields = [v for v in dsets[0].data_vars if "time" in dsets[0][v].dims]
    try:
        combined = xr.concat(dsets, dim=xr.DataArray(ids, dims="member", name="member"), data_vars=fields,
                             coords="minimal", compat="override", join="exact")
    except ValueError as exc:
        raise LagiceError(f"{out_dir}: the members' grids or output times differ, so they cannot share "
                          f"one (member, time, y, x) array: {exc}") from exc
    combined["member"].attrs["long_name"] = "ensemble member id"
    return combined


# -- spread -------------------------------------------------------------------------------
def last_fields(out_dir, members, resolution_m: float | None = None) -> xr.Dataset:
    """Thickness and damage of each member at its last snapshot on one regular grid
    (member, y, x): the members' own grid files when they all have them, else their
    last mesh snapshots averaged conservatively on a common grid (``resolution_m``,
    default the members' median element size)."""
    from ..io.gridded import conservative_grid_average
    from ..io.snapshots import read_index

    out_dir = Path(out_dir)
    dirs = {m: out_dir / "members" / m / "snapshots" for m in members}
    if all(sorted(d.glob("grid_*.nc")) for d in dirs.values()):
        try:
            g = open_grids(out_dir, members=list(members))
            return g[["thickness", "damage"]].isel(time=-1).load()
        except LagiceError:
            pass  # different grids: regrid below
    meshes = {}
    for m, d in dirs.items():
        e = read_index(d)[-1]
        with xr.open_dataset(d / e["file"], decode_times=False) as ds:
            nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
            tri = ds["mesh_face_nodes"].values.astype(np.int64)
            meshes[m] = (nodes, tri, ds["thickness"].values[0], ds["damage"].values[0])
    lo = np.min([v[0].min(axis=0) for v in meshes.values()], axis=0)
    hi = np.max([v[0].max(axis=0) for v in meshes.values()], axis=0)
    if resolution_m is None:
        sizes = []
        for nodes, tri, _, _ in meshes.values():
            a, b = nodes[tri[:, 1]] - nodes[tri[:, 0]], nodes[tri[:, 2]] - nodes[tri[:, 0]]
            sizes.append(np.median(np.sqrt(0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]))))
        resolution_m = float(np.median(sizes)) * 1.5
    nx = max(1, int(np.ceil((hi[0] - lo[0]) / resolution_m)))
    ny = max(1, int(np.ceil((hi[1] - lo[1]) / resolution_m)))
    xe, ye = lo[0] + resolution_m * np.arange(nx + 1), lo[1] + resolution_m * np.arange(ny + 1)
    th, dm = [], []
    for nodes, tri, h, d in meshes.values():
        f, _ = conservative_grid_average(nodes, tri, {"thickness": h, "damage": d}, xe, ye)
        th.append(f["thickness"])
        dm.append(f["damage"])
    coords = {"member": list(members), "y": 0.5 * (ye[1:] + ye[:-1]), "x": 0.5 * (xe[1:] + xe[:-1])}
    return xr.Dataset({"thickness": (("member", "y", "x"), np.array(th), {"units": "m"}),
                       "damage": (("member", "y", "x"), np.array(dm), {"units": "1"})}, coords=coords)


def spread(out_dir, members=None) -> xr.Dataset:
    """Ensemble mean and standard deviation (over finished members, ddof = 0) of
    thickness and damage at the last time, on a regular grid."""
    ids = members or [m for m in member_ids(out_dir) if (Path(out_dir) / "members" / m / "done.json").exists()]
    if not ids:
        raise LagiceError(f"{out_dir}: no finished member")
    f = last_fields(out_dir, ids)
    out = xr.Dataset(coords={"y": f["y"], "x": f["x"]})
    for v in ("thickness", "damage"):
        out[f"{v}_mean"] = f[v].mean("member")
        out[f"{v}_std"] = f[v].std("member")
    out.attrs["members"] = json.dumps(list(ids))
    return out


def plot_spread(out_dir, summary: xr.Dataset, png=None) -> Path | None:
    """PNG: ensemble mean and standard deviation of thickness and damage at the last
    time, and β across members. Returns the path (None when no member finished)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    out_dir = Path(out_dir)
    done = [str(m) for m, s in zip(summary["member"].values, summary["status"].values) if s == "done"]
    if not done:
        return None
    sp = spread(out_dir, done)
    fig = Figure(figsize=(17, 3.9))
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 5)
    x, y = sp["x"].values / 1e3, sp["y"].values / 1e3
    panels = (("thickness_mean", "mean thickness (m)", "viridis"), ("thickness_std", "std thickness (m)", "magma"),
              ("damage_mean", "mean damage", "inferno"), ("damage_std", "std damage", "magma"))
    for ax, (v, title, cmap) in zip(axes, panels):
        im = ax.pcolormesh(x, y, sp[v].values, cmap=cmap, shading="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (km)")
        fig.colorbar(im, ax=ax, shrink=0.8)
    ax = axes[-1]
    beta = summary["beta_space"].values
    ok = np.isfinite(beta)
    if ok.any():
        ax.axvspan(0.17, 0.20, color="0.85", zorder=0, label="RGPS, 10 km, 3 days\n(Marsan et al. 2004)")
        if ok.sum() <= 12:  # few members: one dot per member, labelled
            ids = [str(m) for m in summary["member"].values[ok]]
            ax.plot(beta[ok], np.arange(ok.sum()), "o", color="tab:red")
            ax.set_yticks(np.arange(ok.sum()), [i[:18] for i in ids], fontsize=7)
        else:
            ax.hist(beta[ok], bins=min(20, max(5, int(ok.sum()) // 4)), color="tab:red", alpha=0.8)
            ax.set_ylabel("members")
        ax.legend(fontsize=6)
    else:
        why = sorted({str(s)[:40] for s in summary["diag_status"].values})
        ax.text(0.5, 0.5, "β not available:\n" + "\n".join(why), ha="center", va="center", fontsize=7,
                transform=ax.transAxes)
    ax.set_title(f"β across members ({int(ok.sum())} of {beta.size})", fontsize=9)
    ax.set_xlabel("β")
    t = summary["time_s"].values
    t_last = np.nanmax(t) / 86400 if np.isfinite(t).any() else float("nan")
    fig.suptitle(f"ensemble {summary.attrs.get('ensemble_name')}: {len(done)} finished member(s), "
                 f"fields at day {t_last:.2f}", fontsize=10)
    fig.tight_layout()
    path = Path(png or out_dir / "ensemble_spread.png")
    fig.savefig(path, dpi=100)
    return path
