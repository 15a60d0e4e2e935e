"""Scene ``shear_channel``: a circular (annular) channel of ice in strong shear.

An annulus between an island of radius ``inner_radius_m`` and a coast of
radius ``radius_m``, both coasts (nodes fixed). The ice moves on circles with
the prescribed azimuthal speed

    u_θ(r) = U sin(π (r − r_i) / (R − r_i))      (zero on both coasts, U at mid-channel)

so the mesh is sheared continuously: after 10 days at U = 0.1 m/s the
mid-channel ice has gone round the island ~1.4 times relative to the walls.
Every outer step moves the mesh (:func:`lagice.lagrangian.move_mesh`) and
calls :func:`lagice.remesh.remesh_if_needed`.

Dynamics (``dynamics=``):

* ``"prescribed"`` (default): the ice velocity is the profile above
  (kinematic); the scene exercises mesh motion, remeshing and remapping, and
  a 10-day run at coarse resolution takes seconds. Element fields (a radial
  thickness gradient with noise, concentration, a radial damage band,
  cohesion, stress, snow) are carried and remapped.
* ``"implicit"``: the profile is the **ocean current**; the ice starts at
  rest, undamaged and unstressed, with weak cohesion ``cohesion_pa``, and is
  driven by quadratic ocean drag through the
  :class:`~lagice.solvers.implicit.ImplicitSolver` (Maxwell-EB). It breaks
  along the walls and is dragged round the channel. Δt = 1 h ≫ td, so the
  linear systems are stiff: the default linear solver is the direct
  ``"superlu"`` (CG stalls at 5 km resolution).

Outputs: ``shear_channel.nc`` (time series of totals, remesh events and
timings; final UGRID mesh and fields) and ``shear_channel.png``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, check_range
from ..lagrangian import move_mesh, new_budget
from ..mesh import generate_mesh
from ..remesh import RemeshLog, TriggerParams, remesh_if_needed, totals
from ..state import IceState

DAY_S = 86400.0


@dataclass
class ShearChannelScene:
    state: IceState
    size_m: float
    radius_m: float
    inner_radius_m: float
    speed_m_s: float
    dt_s: float
    solver: object = None
    budget: dict = field(default_factory=new_budget)
    log: RemeshLog = field(default_factory=RemeshLog)
    timings: dict = field(default_factory=lambda: {"solver": 0.0, "move": 0.0, "remesh": 0.0})

    def velocity(self, xy: np.ndarray) -> np.ndarray:
        """Prescribed velocity [m s-1] at positions ``xy`` (n, 2) [m]."""
        r = np.hypot(xy[:, 0], xy[:, 1])
        s = np.clip((r - self.inner_radius_m) / (self.radius_m - self.inner_radius_m), 0.0, 1.0)
        ut = self.speed_m_s * np.sin(np.pi * s)
        with np.errstate(invalid="ignore", divide="ignore"):
            ex, ey = -xy[:, 1] / r, xy[:, 0] / r
        return np.column_stack([ut * ex, ut * ey])


def build(size_m: float = 10e3, radius_m: float = 100e3, inner_radius_m: float = 30e3,
          speed_m_s: float = 0.1, dt_s: float = 3600.0, seed: int = 0, dynamics: str = "prescribed",
          cohesion_pa: float = 1e3, linear_solver: str = "superlu") -> ShearChannelScene:
    """Mesh the annulus and set up the initial ice (see module docstring)."""
    import shapely

    if dynamics not in ("prescribed", "implicit"):
        raise ConfigError(f"dynamics = {dynamics!r}; expected 'prescribed' or 'implicit'")
    check_range("cohesion_pa", cohesion_pa, 0.0, None, low_open=True, unit="Pa")
    check_range("size_m", size_m, 0.0, None, low_open=True, unit="m")
    check_range("radius_m", radius_m, 0.0, None, low_open=True, unit="m")
    check_range("inner_radius_m", inner_radius_m, 0.0, radius_m, low_open=True, high_open=True, unit="m")
    check_range("speed_m_s", speed_m_s, 0.0, None, unit="m s-1")
    check_range("dt_s", dt_s, 0.0, None, low_open=True, unit="s")
    n_out = max(12, int(np.ceil(2 * np.pi * radius_m / size_m)))
    n_in = max(8, int(np.ceil(2 * np.pi * inner_radius_m / size_m)))
    t_out = np.linspace(0, 2 * np.pi, n_out, endpoint=False)
    t_in = np.linspace(0, 2 * np.pi, n_in, endpoint=False)
    outer = np.column_stack([radius_m * np.cos(t_out), radius_m * np.sin(t_out)])
    inner = np.column_stack([inner_radius_m * np.cos(t_in), inner_radius_m * np.sin(t_in)])
    poly = shapely.Polygon(outer, [inner])
    mesh = generate_mesh(poly, size_m)
    rng = np.random.default_rng(seed)
    m = mesh.n_elements
    c = mesh.centroids()
    r = np.hypot(c[:, 0], c[:, 1])
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=25e3)
    st.thickness = 0.5 + 1.5 * (r - inner_radius_m) / (radius_m - inner_radius_m) + rng.uniform(0, 0.2, m)
    st.concentration = rng.uniform(0.8, 1.0, m)
    band = np.abs(c[:, 1]) < 0.6 * size_m
    st.damage = np.where(band & (c[:, 0] > 0), 0.95, rng.uniform(0.0, 0.1, m))
    st.cohesion = rng.uniform(20e3, 30e3, m)
    st.stress = rng.normal(0.0, 1e3, (m, 3))
    st.snow = rng.uniform(0.0, 0.3, m)
    sc = ShearChannelScene(st, float(size_m), float(radius_m), float(inner_radius_m), float(speed_m_s),
                           float(dt_s))
    if dynamics == "implicit":
        from ..forces import OceanDrag
        from ..rheology import MaxwellEB
        from ..solvers.implicit import ImplicitSolver

        st.velocity = np.zeros((mesh.n_nodes, 2))
        st.stress[:] = 0.0
        st.damage[:] = 0.0
        st.cohesion[:] = cohesion_pa

        def current(t, x, y):
            return sc.velocity(np.column_stack([x, y])).T

        sc.solver = ImplicitSolver(MaxwellEB(), mesh, forces=[OceanDrag(current=current, min_speed=1e-3)],
                                   max_iter=10, tol=1e-6, linear_solver=linear_solver)
    else:
        st.velocity = sc.velocity(mesh.nodes)
    return sc


def step(sc: ShearChannelScene, params: TriggerParams | None = None):
    """One outer step: velocity (prescribed or ImplicitSolver), Lagrangian
    move, remesh if needed. Wall times accumulate in ``sc.timings``."""
    st = sc.state
    t0 = time.perf_counter()
    if sc.solver is None:
        st.velocity = sc.velocity(st.mesh.nodes)
        st.time_s += sc.dt_s
        st.step += 1
    else:
        sc.solver.step(st, sc.dt_s)  # advances time and step
    t1 = time.perf_counter()
    rep = move_mesh(st, sc.dt_s, sc.budget, solver=sc.solver)
    t2 = time.perf_counter()
    ev = remesh_if_needed(st, sc.size_m, solver=sc.solver, params=params, flagged=rep.flagged_elements,
                          log=sc.log)
    t3 = time.perf_counter()
    sc.timings["solver"] += t1 - t0
    sc.timings["move"] += t2 - t1
    sc.timings["remesh"] += t3 - t2
    return rep, ev


def run(out_dir="runs/shear_channel", days: float = 10.0, progress: bool = True, plot: bool = True,
        **build_kw) -> dict:
    """Run ``days`` of the scene (``build_kw`` go to :func:`build`); write
    netCDF and PNG; return the time series."""
    check_range("days", days, 0.0, 3650.0, low_open=True, unit="day")
    sc = build(**build_kw)
    n_steps = int(np.ceil(days * DAY_S / sc.dt_s))
    t0_tot = totals(sc.state.mesh, sc.state)
    ts = {k: np.zeros(n_steps) for k in ("time", "ice_volume", "ice_area", "n_elements",
                                         "min_angle", "remeshed", "wall_solver", "wall_move",
                                         "wall_remesh")}
    from ..mesh import angles_deg

    t_start = time.perf_counter()
    for k in range(n_steps):
        tm0 = dict(sc.timings)
        _, ev = step(sc)
        st = sc.state
        tt = totals(st.mesh, st)
        ts["time"][k] = st.time_s
        ts["ice_volume"][k] = tt["ice_volume_m3"]
        ts["ice_area"][k] = tt["ice_area_m2"]
        ts["n_elements"][k] = st.mesh.n_elements
        ts["min_angle"][k] = angles_deg(st.mesh.nodes, st.mesh.triangles).min()
        ts["remeshed"][k] = 0 if ev is None else 1
        ts["wall_solver"][k] = sc.timings["solver"] - tm0["solver"]
        ts["wall_move"][k] = sc.timings["move"] - tm0["move"]
        ts["wall_remesh"][k] = sc.timings["remesh"] - tm0["remesh"]
        if progress and (k % max(1, n_steps // 10) == 0 or k == n_steps - 1):
            print(f"  step {k + 1}/{n_steps}  day {st.time_s / DAY_S:.2f}  elements {st.mesh.n_elements}  "
                  f"remesh events {len(sc.log)}  volume error "
                  f"{(tt['ice_volume_m3'] - t0_tot['ice_volume_m3']) / t0_tot['ice_volume_m3']:.2e}",
                  flush=True)
    wall = time.perf_counter() - t_start
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    nc = _write_netcdf(out / "shear_channel.nc", sc, ts, t0_tot, wall)
    png = _plot(nc, out / "shear_channel.png") if plot else None
    return {"netcdf": nc, "png": png, "timeseries": ts, "scene": sc, "wall_s": wall,
            "initial_totals": t0_tot, "remesh_summary": sc.log.summary(), "budget": dict(sc.budget),
            "timings": dict(sc.timings)}


def _write_netcdf(path, sc, ts, t0_tot, wall):
    from ..io.ugrid import mesh_dataset

    st = sc.state
    ds = mesh_dataset(st.mesh)
    ds["time"] = ("time", ts["time"], {"units": "s", "long_name": "time since start"})
    ds["ice_volume"] = ("time", ts["ice_volume"], {"units": "m3", "long_name": "total ice volume"})
    ds["ice_area"] = ("time", ts["ice_area"], {"units": "m2", "long_name": "total ice area"})
    ds["n_elements"] = ("time", ts["n_elements"].astype(np.int32), {"units": "1"})
    ds["min_angle"] = ("time", ts["min_angle"], {"units": "degree", "long_name": "smallest mesh angle"})
    ds["remeshed"] = ("time", ts["remeshed"].astype(np.int8), {"units": "1"})
    ds["wall_solver"] = ("time", ts["wall_solver"], {"units": "s"})
    ds["wall_move"] = ("time", ts["wall_move"], {"units": "s"})
    ds["wall_remesh"] = ("time", ts["wall_remesh"], {"units": "s"})
    for name, units in (("thickness", "m"), ("concentration", "1"), ("damage", "1")):
        ds[name] = ("mesh_face", getattr(st, name), {"units": units, "mesh": "mesh", "location": "face"})
    summ = sc.log.summary()
    ds.attrs.update({
        "title": "lagice shear_channel (annulus in prescribed shear; mesh motion + remeshing)",
        "size_m": sc.size_m, "dt_s": sc.dt_s, "speed_m_s": sc.speed_m_s, "wall_time_s": wall,
        "dynamics": "prescribed" if sc.solver is None else "implicit",
        "initial_ice_volume_m3": t0_tot["ice_volume_m3"], "n_remesh_events": summ.get("n_events", 0),
        "n_global_remesh": summ.get("n_global", 0), "remesh_wall_s": summ.get("t_total_s", 0.0),
        "ridged_elements": int(sc.budget["ridged_elements"]), "limited_nodes": int(sc.budget["limited_nodes"]),
        "Conventions": "CF-1.8 UGRID-1.0",
    })
    ds.to_netcdf(path)
    return Path(path)


def _plot(nc_path, png_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri
    import xarray as xr

    ds = xr.load_dataset(nc_path)
    tri = mtri.Triangulation(ds["mesh_node_x"].values / 1e3, ds["mesh_node_y"].values / 1e3,
                             ds["mesh_face_nodes"].values)
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.4))
    pc = ax[0].tripcolor(tri, ds["damage"].values, vmin=0, vmax=1, cmap="magma_r", edgecolors="0.7",
                         linewidth=0.1)
    ax[0].set_aspect("equal")
    ax[0].set_title("damage and mesh at the end")
    fig.colorbar(pc, ax=ax[0])
    pc = ax[1].tripcolor(tri, ds["thickness"].values, cmap="viridis")
    ax[1].set_aspect("equal")
    ax[1].set_title("thickness h (m)")
    fig.colorbar(pc, ax=ax[1])
    t = ds["time"].values / DAY_S
    v = ds["ice_volume"].values
    ax[2].plot(t, (v - ds.attrs["initial_ice_volume_m3"]) / ds.attrs["initial_ice_volume_m3"], "k-")
    ax[2].set_xlabel("time (days)")
    ax[2].set_ylabel("relative ice-volume change")
    ax[2].set_title(f"{ds.attrs['n_remesh_events']} remesh events")
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    plt.close(fig)
    return Path(png_path)
