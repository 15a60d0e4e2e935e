"""Plots of a run: maps of the last snapshot and a one-page summary."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .io.cf import save_figure_atomic


def _tri(ds):
    import matplotlib.tri as mtri

    return mtri.Triangulation(ds["mesh_node_x"].values / 1e3, ds["mesh_node_y"].values / 1e3,
                              ds["mesh_face_nodes"].values)


def plot_run(snap_dir, png_path, summary: dict | None = None, trajectories=None) -> Path:
    """Damage, total deformation rate, thickness and concentration of the last
    snapshot, drifter trajectories (if given, list of (n_t, 2) arrays in m) and
    a text panel with the run summary."""
    import xarray as xr
    from matplotlib.figure import Figure

    snap_dir = Path(snap_dir)
    index = json.loads((snap_dir / "index.json").read_text())
    last = index[-1]
    ds = xr.load_dataset(snap_dir / last["file"])
    tri = _tri(ds)
    panels = [("damage", "damage", "magma_r", (0, 1)),
              ("total_deformation_rate", "log10 total deformation rate (s⁻¹)", "viridis", None),
              ("thickness", "thickness h (m)", "Blues", None),
              ("concentration", "concentration A", "cividis", None)]
    fig = Figure(figsize=(15, 9.5))
    axes = fig.subplots(2, 3)
    axes = axes.ravel()
    for ax, (name, title, cmap, lim) in zip(axes[:4], panels):
        if name not in ds:
            ax.set_visible(False)
            continue
        v = ds[name].values[0]
        if name == "concentration":
            lim = (min(float(v.min()), 0.999), 1.0)
        if name == "total_deformation_rate":
            v = np.log10(np.maximum(v, 1e-12))
            vmax = float(np.nanmax(v))
            lim = (vmax - 3.0, vmax)
        pc = ax.tripcolor(tri, v, cmap=cmap, vmin=None if lim is None else lim[0],
                          vmax=None if lim is None else lim[1])
        ax.set_aspect("equal")
        ax.set_title(f"{title}\nday {last['time_s'] / 86400:.2f}", fontsize=10)
        ax.set_xlabel("x (km)")
        ax.set_ylabel("y (km)")
        fig.colorbar(pc, ax=ax, shrink=0.8)
    ax = axes[4]
    ax.triplot(tri, lw=0.2, color="0.8")
    if trajectories:
        for tr in trajectories:
            tr = np.asarray(tr) / 1e3
            ax.plot(tr[:, 0], tr[:, 1], "-", lw=1.2)
            ax.plot(tr[-1, 0], tr[-1, 1], "o", ms=3)
        ax.set_title("drifter trajectories over the mesh")
    else:
        ax.set_title("final mesh")
    ax.set_aspect("equal")
    ax = axes[5]
    ax.axis("off")
    lines = []
    if summary:
        lines.append(f"scene: {summary.get('scene', '?')}")
        lines.append(f"simulated: {summary.get('time_s', 0) / 86400:.2f} days in {summary.get('steps', 0)} steps")
        lines.append(f"wall time: {summary.get('wall_s', 0):.1f} s")
        for k, v in (summary.get("timings") or {}).items():
            lines.append(f"  {k}: {v:.1f} s")
        lines.append(f"remesh events: {summary.get('remesh_count', 0)}")
        if "volume_budget" in summary:
            for k, v in summary["volume_budget"].items():
                if isinstance(v, (int, float)):
                    lines.append(f"  {k}: {v:.6g}")
        lines.append(f"ice volume: {summary.get('ice_volume_m3', float('nan')):.6g} m³")
    lines.append(f"snapshots: {len(index)} (mesh epochs {index[0]['mesh_epoch']}–{index[-1]['mesh_epoch']})")
    ax.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize=9)
    fig.tight_layout()
    save_figure_atomic(fig, png_path, dpi=100)
    return Path(png_path)
