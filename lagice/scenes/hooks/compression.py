"""Hooks of the ``uniaxial_compression`` scene (Dansereau et al. 2016, §4, Table 1,
Fig. 5): the macroscopic stress and strain of the plate as time-series
diagnostics, and the scene's figure.

The plate is L/2 × L (L = ``domain.height_m``); the top edge is pushed down at
U = −``boundary.top.v``, the bottom edge is fixed in the pushing direction.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...io.cf import save_figure_atomic
from ...io.timeseries import diagnostic

_EDGE_CACHE = {}


def edge_elements(mesh, tag: str):
    """Element owning each edge tagged ``tag`` and the edge lengths [m]."""
    key = (id(mesh), mesh.n_elements, tag)
    hit = _EDGE_CACHE.get(key)
    if hit is not None and hit[0] is mesh:
        return hit[1], hit[2]
    edges = mesh.edges_with_tag(tag)
    tri = mesh.triangles
    n = np.int64(mesh.n_nodes)
    keys = np.concatenate([tri[:, k] * n + tri[:, (k + 1) % 3] for k in range(3)])
    elem = np.tile(np.arange(len(tri)), 3)
    order = np.argsort(keys)
    pos = np.searchsorted(keys[order], edges[:, 0] * n + edges[:, 1])
    el = elem[order][pos]
    d = mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]]
    ln = np.hypot(d[:, 0], d[:, 1])
    _EDGE_CACHE.clear()
    _EDGE_CACHE[key] = (mesh, el, ln)
    return el, ln


@diagnostic("Pa", "macroscopic stress: sigma_yy integrated on the top edge / edge length "
                  "(tension positive; compression negative)")
def macro_stress(model) -> float:
    """σyy integrated along the top edge divided by its length [Pa, tension positive]."""
    el, ln = edge_elements(model.mesh, "top")
    return float(np.sum(model.state.stress[el, 1] * ln) / np.sum(ln))


@diagnostic("1", "macroscopic compressive strain U t / L")
def macro_strain(model) -> float:
    """U t / L with U the push speed of the top edge and L the plate length."""
    cfg = model.config
    u = -float(cfg["boundary"]["top"]["v"])
    return u * model.clock.time_s / float(cfg["domain"]["height_m"])


def first_peak(stress, drop: float = 0.02) -> int:
    """Index of the stress peak before the first macroscopic drop of more than ``drop``
    (relative to the running maximum); the global maximum when there is no drop."""
    s = np.asarray(stress, np.float64)
    if s.size == 0:
        return 0
    runmax = np.maximum.accumulate(s)
    dd = (runmax - s) / np.maximum(runmax, 1e-30)
    dd[runmax < 0.5 * s.max()] = 0.0
    k = int(np.argmax(dd > drop))
    return int(np.argmax(s[:k])) if dd[k] > drop and k > 0 else int(np.argmax(s))


def plot(run_dir, png_path, summary=None) -> Path:
    """Dansereau et al. (2016) Fig. 5-like figure: macroscopic stress–strain curve with
    the damage rate, then damage and log10 total deformation rate maps at the first
    snapshot after the stress peak and at the end."""
    import json

    import matplotlib.tri as mtri
    import xarray as xr
    from matplotlib.figure import Figure

    run_dir = Path(run_dir)
    ts = xr.load_dataset(run_dir / "timeseries.nc", decode_times=False)
    snaps = run_dir / "snapshots"
    index = json.loads((snaps / "index.json").read_text())
    cfg = json.loads(ts.attrs.get("lagice_config", "{}"))
    t = ts["time"].values
    strain = ts["macro_strain"].values
    stress_kpa = -ts["macro_stress"].values / 1e3
    md = ts["mean_damage"].values
    rate = np.gradient(md, t) if len(t) > 1 else np.zeros_like(md)
    ipk = first_peak(stress_kpa)
    snap_t = np.array([e["time_s"] for e in index])
    after = np.flatnonzero(snap_t >= t[ipk])
    picks = sorted({int(after[0]) if len(after) else len(snap_t) - 1, len(snap_t) - 1})
    ncol = 1 + 2 * len(picks)
    fig = Figure(figsize=(3.2 * ncol, 5.2))
    gs = fig.add_gridspec(1, ncol, width_ratios=[2.2] + [1] * (ncol - 1))
    ax = fig.add_subplot(gs[0])
    ax.plot(strain * 1e3, stress_kpa, "k-", lw=1.2, label="macroscopic stress")
    ax.set_xlabel("macroscopic strain (×10⁻³)")
    ax.set_ylabel("compressive stress (kPa)")
    ax2 = ax.twinx()
    ax2.plot(strain * 1e3, rate, color="0.6", lw=0.8, label="damage rate")
    ax2.set_ylabel("rate of area-mean damage (s⁻¹)", color="0.4")
    for i in picks:
        ax.axvline(np.interp(snap_t[i], t, strain) * 1e3, color="tab:blue", ls=":", lw=0.8)
    dom = cfg.get("domain", {})
    n_across = dom.get("width_m", 0) / dom.get("resolution_m", 1) if dom else float("nan")
    ax.set_title(f"N = {n_across:.0f}, peak {stress_kpa[ipk]:.0f} kPa")
    col = 1
    for i in picks:
        ds = xr.load_dataset(snaps / index[i]["file"], decode_times=False)
        tri = mtri.Triangulation(ds["mesh_node_x"].values / 1e3, ds["mesh_node_y"].values / 1e3,
                                 ds["mesh_face_nodes"].values)
        a = fig.add_subplot(gs[col])
        pc = a.tripcolor(tri, ds["damage"].values[0], vmin=0, vmax=1, cmap="magma_r")
        a.set_aspect("equal")
        a.set_title(f"damage, t = {snap_t[i] / 3600:.1f} h", fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
        fig.colorbar(pc, ax=a, orientation="horizontal", fraction=0.05, pad=0.03)
        b = fig.add_subplot(gs[col + 1])
        if "total_deformation_rate" in ds:
            lg = np.log10(np.maximum(ds["total_deformation_rate"].values[0], 1e-30))
            vmax = np.nanmax(lg)
            pc = b.tripcolor(tri, lg, vmin=vmax - 3, vmax=vmax, cmap="viridis")
            fig.colorbar(pc, ax=b, orientation="horizontal", fraction=0.05, pad=0.03)
        b.set_aspect("equal")
        b.set_title("log10 total deformation rate (s⁻¹)", fontsize=9)
        b.set_xticks([])
        b.set_yticks([])
        col += 2
    fig.tight_layout()
    save_figure_atomic(fig, png_path, dpi=110)
    return Path(png_path)
