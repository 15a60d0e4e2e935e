"""Scene ``uniaxial_compression`` (seed 004 §4, Table 1, Fig. 4).

A plate L/2 × L (L = 200 km) of undamaged ice, 1 m thick, concentration 1.
The top edge is pushed down at U = 1e-3 m/s (v = −U, u free), the bottom edge
is fixed in the pushing direction (v = 0, u free), the sides are free.
N elements across the short edge (Δx = L/(2N)), Δt = Δx/cs.

Outputs: ``compression.nc`` (macroscopic stress/strain time series, damage
and strain-rate snapshots, UGRID mesh) and ``compression.png`` (seed 004
Fig. 5-like: stress–strain curve, damage maps, log10 total strain-rate maps).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..deformation import invariants
from ..errors import ConfigError, check_range
from ..mesh import generate_mesh, rectangle_domain
from ..params import MaxwellEBParams
from ..rheology import MaxwellEB, draw_cohesion
from ..solvers import SOLVERS, VelocityBC
from ..state import IceState

PLATE_LENGTH_M = 200e3
PUSH_SPEED_M_S = 1e-3


@dataclass
class CompressionScene:
    mesh: object
    state: IceState
    solver: object
    dt_s: float
    dx_m: float
    n_across: int
    top_edge_elements: np.ndarray
    top_edge_lengths: np.ndarray
    width_m: float
    length_m: float
    push_speed_m_s: float


def build(n_across: int = 40, seed: int = 0, solver: str = "implicit", healing: bool = True,
          linear_solver: str = "cg", dt_s: float | None = None, rheology: dict | None = None,
          length_m: float = PLATE_LENGTH_M, push_speed_m_s: float = PUSH_SPEED_M_S,
          **solver_options) -> CompressionScene:
    """Build mesh, initial state and solver of the compression test.

    Bad parameters raise :class:`~lagice.errors.ConfigError` before any mesh work.
    """
    if int(n_across) != n_across:
        raise ConfigError(f"n_across = {n_across!r} must be an integer")
    check_range("n_across", n_across, 2, 400)
    check_range("length_m", length_m, 0.0, None, low_open=True, unit="m")
    check_range("push_speed_m_s", push_speed_m_s, 0.0, None, low_open=True, unit="m s-1")
    if solver not in SOLVERS:
        raise ConfigError(f"solver = {solver!r} is unknown; expected one of {sorted(SOLVERS)}")
    rheo_kw = dict(rheology or {})
    if not healing:
        rheo_kw["healing_time_s"] = None
    params = MaxwellEBParams().replace(**rheo_kw)
    n_across = int(n_across)
    width = 0.5 * length_m
    dx = width / n_across
    if dt_s is None:
        dt_s = dx / params.shear_wave_speed
    check_range("dt_s", dt_s, 0.0, None, low_open=True, unit="s")
    poly, segs = rectangle_domain(width, length_m)
    mesh = generate_mesh(poly, dx, segments={"top": segs["top"], "bottom": segs["bottom"]},
                         exterior_tag="free")
    rng = np.random.default_rng(seed)
    rheo = MaxwellEB(params)
    state = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0,
                             cohesion_pa=draw_cohesion(mesh.n_elements, params, rng))
    state.counters["seed"] = seed
    bcs = [VelocityBC("top", v=-push_speed_m_s), VelocityBC("bottom", v=0.0)]
    if solver == "implicit":  # solver-specific options (explicit: substeps=, safety=, ...)
        solver_options["linear_solver"] = linear_solver
    solv = SOLVERS[solver](rheo, mesh, bcs=bcs, **solver_options)
    el, ln = edge_elements(mesh, "top")
    return CompressionScene(mesh, state, solv, float(dt_s), dx, n_across, el, ln, width, length_m,
                            push_speed_m_s)


def edge_elements(mesh, tag):
    """Element owning each edge tagged ``tag`` and the edge lengths [m]."""
    edges = mesh.edges_with_tag(tag)
    tri = mesh.triangles
    key = {}
    for k in range(3):
        a, b = tri[:, k], tri[:, (k + 1) % 3]
        for e, (i, j) in enumerate(zip(a, b)):
            key[(i, j)] = e
    el = np.array([key[(i, j)] for i, j in edges], dtype=np.int64)
    d = mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]]
    return el, np.hypot(d[:, 0], d[:, 1])


def macro_stress(scene: CompressionScene) -> float:
    """Macroscopic stress [Pa, tension positive]: σyy integrated along the top
    edge divided by the edge length (force per unit thickness per unit length)."""
    s = scene.state.stress[scene.top_edge_elements, 1]
    return float(np.sum(s * scene.top_edge_lengths) / np.sum(scene.top_edge_lengths))


def run(out_dir="runs/uniaxial_compression", n_across: int = 40, seed: int = 0,
        max_strain: float = 5e-4, n_snapshots: int = 8, progress: bool = True, plot: bool = True,
        **build_kw) -> dict:
    """Run the compression scene up to macroscopic strain ``max_strain`` and write outputs.

    Returns a dict with the output paths and the time series arrays.
    """
    check_range("max_strain", max_strain, 0.0, 0.5, low_open=True)
    sc = build(n_across=n_across, seed=seed, **build_kw)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t_end = max_strain * sc.length_m / sc.push_speed_m_s
    n_steps = int(np.ceil(t_end / sc.dt_s))
    snap_every = max(1, n_steps // max(1, n_snapshots))
    ts = {k: np.zeros(n_steps) for k in ("time", "strain", "stress", "mean_damage", "damage_rate",
                                         "iterations", "n_damaged", "wall")}
    snaps = {"time": [], "damage": [], "strain_rate_total": [], "stress": []}
    t0 = time.perf_counter()
    last_print = t0
    timings = {"assembly": 0.0, "solve": 0.0, "damage": 0.0}
    n_capped = 0
    md_prev = 0.0
    for k in range(n_steps):
        info = sc.solver.step(sc.state, sc.dt_s)
        for key, v in info.timings.items():
            timings[key] += v
        n_capped += info.n_capped
        st = sc.state
        md = float(np.average(st.damage, weights=sc.solver.area))
        ts["time"][k] = st.time_s
        ts["strain"][k] = sc.push_speed_m_s * st.time_s / sc.length_m
        ts["stress"][k] = macro_stress(sc)
        ts["mean_damage"][k] = md
        ts["damage_rate"][k] = (md - md_prev) / sc.dt_s
        ts["iterations"][k] = info.iterations
        ts["n_damaged"][k] = info.n_damaged
        md_prev = md
        if (k + 1) % snap_every == 0 or k == n_steps - 1:
            _, _, tot = invariants(sc.solver.last_strain_rate)
            snaps["time"].append(st.time_s)
            snaps["damage"].append(st.damage.copy())
            snaps["strain_rate_total"].append(tot)
            snaps["stress"].append(st.stress.copy())
        now = time.perf_counter()
        if progress and (now - last_print > 5.0 or k == n_steps - 1):
            last_print = now
            print(f"  step {k + 1}/{n_steps}  t = {st.time_s / 3600:.2f} h  strain = {ts['strain'][k]:.2e}  "
                  f"stress = {-ts['stress'][k] / 1e3:.1f} kPa (compressive)  mean damage = {md:.4f}  "
                  f"[{now - t0:.0f} s wall]", flush=True)
    wall = time.perf_counter() - t0
    nc = write_netcdf(out / "compression.nc", sc, ts, snaps, timings, wall, n_capped)
    png = plot_compression(nc, out / "compression.png") if plot else None
    return {"netcdf": nc, "png": png, "timeseries": ts, "snapshots": snaps, "wall_s": wall,
            "timings": timings, "scene": sc, "n_capped": n_capped}


def write_netcdf(path, sc: CompressionScene, ts, snaps, timings, wall, n_capped) -> Path:
    from ..io.ugrid import mesh_dataset

    ds = mesh_dataset(sc.mesh)
    ds["time"] = ("time", ts["time"], {"units": "s", "long_name": "time since start"})
    ds["macro_strain"] = ("time", ts["strain"], {"units": "1", "long_name":
                          "macroscopic compressive strain U t / L"})
    ds["macro_stress"] = ("time", ts["stress"], {"units": "Pa", "long_name":
                          "macroscopic stress: sigma_yy integrated on the top edge / edge length "
                          "(tension positive; compression negative)"})
    ds["mean_damage"] = ("time", ts["mean_damage"], {"units": "1", "long_name": "area-mean damage"})
    ds["damage_rate"] = ("time", ts["damage_rate"], {"units": "s-1",
                         "long_name": "rate of change of area-mean damage"})
    ds["fixed_point_iterations"] = ("time", ts["iterations"].astype(np.int32), {"units": "1"})
    ds["n_damaged_elements"] = ("time", ts["n_damaged"].astype(np.int32), {"units": "1"})
    ds["snapshot_time"] = ("snapshot", np.array(snaps["time"]), {"units": "s"})
    ds["damage"] = (("snapshot", "mesh_face"), np.array(snaps["damage"]),
                    {"units": "1", "long_name": "damage (0 undamaged, 1 fully damaged)",
                     "mesh": "mesh", "location": "face"})
    ds["strain_rate_total"] = (("snapshot", "mesh_face"), np.array(snaps["strain_rate_total"]),
                               {"units": "s-1", "long_name": "total strain rate sqrt(div^2+shear^2)",
                                "mesh": "mesh", "location": "face"})
    ds["stress"] = (("snapshot", "mesh_face", "stress_component"), np.array(snaps["stress"]),
                    {"units": "Pa", "long_name": "internal stress (xx, yy, xy), tension positive",
                     "mesh": "mesh", "location": "face"})
    ds["cohesion"] = ("mesh_face", sc.state.cohesion, {"units": "Pa", "mesh": "mesh", "location": "face"})
    ds.attrs.update({
        "title": "lagice uniaxial_compression (seed 004 section 4)",
        "n_across": sc.n_across, "dx_m": sc.dx_m, "dt_s": sc.dt_s, "plate_width_m": sc.width_m,
        "plate_length_m": sc.length_m, "push_speed_m_s": sc.push_speed_m_s,
        "young_modulus_pa": sc.solver.rheology.E0, "seed": int(sc.state.counters.get("seed", 0)),
        "solver": sc.solver.name, "wall_time_s": wall,
        "wall_assembly_s": timings["assembly"], "wall_solve_s": timings["solve"],
        "wall_damage_s": timings["damage"], "n_damage_capped": int(n_capped),
        "Conventions": "CF-1.8 UGRID-1.0",
    })
    path = Path(path)
    ds.to_netcdf(path)
    return path


def plot_compression(nc_path, png_path) -> Path:
    """Seed 004 Fig. 5-like figure from the netCDF output."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri
    import xarray as xr

    ds = xr.load_dataset(nc_path)
    x, y = ds["mesh_node_x"].values / 1e3, ds["mesh_node_y"].values / 1e3
    tri = mtri.Triangulation(x, y, ds["mesh_face_nodes"].values)
    strain = ds["macro_strain"].values
    stress_kpa = -ds["macro_stress"].values / 1e3
    ipk = int(np.argmax(stress_kpa))
    snap_t = ds["snapshot_time"].values
    t_pk = ds["time"].values[ipk]
    after = np.flatnonzero(snap_t >= t_pk)
    picks = [int(after[0]) if len(after) else len(snap_t) - 1, len(snap_t) - 1]
    picks = sorted(set(picks))
    ncol = 1 + 2 * len(picks)
    fig = plt.figure(figsize=(3.2 * ncol, 5.2))
    gs = fig.add_gridspec(1, ncol, width_ratios=[2.2] + [1] * (ncol - 1))
    ax = fig.add_subplot(gs[0])
    ax.plot(strain * 1e3, stress_kpa, "k-", lw=1.2, label="macroscopic stress")
    ax.set_xlabel("macroscopic strain (×10⁻³)")
    ax.set_ylabel("compressive stress (kPa)")
    ax2 = ax.twinx()
    ax2.plot(strain * 1e3, ds["damage_rate"].values, color="0.6", lw=0.8, label="damage rate")
    ax2.set_ylabel("damage rate (s⁻¹)", color="0.4")
    for i in picks:
        s = ds["macro_strain"].values[np.searchsorted(ds["time"].values, snap_t[i])
                                      .clip(0, len(strain) - 1)]
        ax.axvline(s * 1e3, color="tab:blue", ls=":", lw=0.8)
    ax.set_title(f"N = {ds.attrs['n_across']}, E0 = {ds.attrs['young_modulus_pa'] / 1e6:.0f} MPa")
    col = 1
    for i in picks:
        a = fig.add_subplot(gs[col])
        pc = a.tripcolor(tri, ds["damage"].values[i], vmin=0, vmax=1, cmap="magma_r")
        a.set_aspect("equal")
        a.set_title(f"damage, t = {snap_t[i] / 3600:.1f} h", fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
        fig.colorbar(pc, ax=a, orientation="horizontal", fraction=0.05, pad=0.03)
        b = fig.add_subplot(gs[col + 1])
        er = ds["strain_rate_total"].values[i]
        lg = np.log10(np.maximum(er, 1e-30))
        vmax = np.nanmax(lg)
        pc = b.tripcolor(tri, lg, vmin=vmax - 3, vmax=vmax, cmap="viridis")
        b.set_aspect("equal")
        b.set_title("log10 total strain rate (s⁻¹)", fontsize=9)
        b.set_xticks([])
        b.set_yticks([])
        fig.colorbar(pc, ax=b, orientation="horizontal", fraction=0.05, pad=0.03)
        col += 2
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    return Path(png_path)
