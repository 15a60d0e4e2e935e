"""Remeshing benchmark (issue 4).

1. Supermesh intersection: numba grid + Sutherland–Hodgman clipper
   (``method="clip"``) against ``numba_celltree.CellTree2d.intersect_faces``
   (``method="celltree"``), old/new meshes of ~20k and ~200k elements.
2. Sheared scene (``shear_channel``: annulus, prescribed shear, Lagrangian
   motion + the remeshing component after every outer step of 1 h; scene builder +
   Simulation, the path of ``lagice run``) at ~20k and ~200k elements: remesh
   events per simulated day, time per event split into gmsh and remapping
   (the remesher's event log), elements touched, the wall time of mesh motion and
   remeshing (``model.timings``) and the share of run time spent remeshing. The
   velocity is prescribed, so the "total" of a dynamic run is estimated as the
   measured kinematic run plus one implicit step (Δt = td) per outer step, timed on
   ``shear_channel_implicit`` at the same resolution (a lower bound on the dynamic
   cost, so the printed remesh share is an upper bound).
3. ``shear_channel_implicit`` (implicit Maxwell-EB dynamics, ice dragged by the
   sheared ocean current, 1-h steps) for 10 days at ``--dynamic-size`` (8 km, ~1.1k
   elements by default): the measured share of remeshing in a real dynamic run.

    python benchmarks/bench_remesh.py              # 20k for 10 days, 200k for 6 days
    python benchmarks/bench_remesh.py --quick      # smaller, for a smoke test
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scene_runs import reset_timings, scene_simulation, timed_run

from lagice.mesh import generate_mesh, rectangle_domain
from lagice.remesh import intersect_triangles

DAY = 86400.0


def channel_overrides(size_m: float) -> dict:
    """The annulus meshed at ``size_m`` (its polygon's vertices at the same spacing)."""
    return {"domain.resolution_m": size_m, "domain.params.vertex_spacing_m": size_m, "output.timeseries": None}


def bench_intersect(n_target):
    poly, _ = rectangle_domain(100e3, 100e3)
    s = 100e3 / np.sqrt(n_target / 2.3)
    a = generate_mesh(poly, s)
    b = generate_mesh(poly, 0.9 * s)
    out = {"n_old": a.n_elements, "n_new": b.n_elements}
    for method in ("clip", "celltree"):
        intersect_triangles(a.nodes, a.triangles[:10], b.nodes, b.triangles[:10], method=method)  # compile
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            i, j, w = intersect_triangles(a.nodes, a.triangles, b.nodes, b.triangles, method=method)
            best = min(best, time.perf_counter() - t0)
        out[f"{method}_s"] = best
        out[f"{method}_pairs"] = int(len(w))
        out[f"{method}_area_rel_err"] = float(abs(w.sum() - 1e10) / 1e10)
    return out


def implicit_step_time(size_m, n=3):  # -> (seconds per step, dt_s)
    """Wall time of one implicit step of Δt = td = Δx/cs on ``shear_channel_implicit``
    at ``size_m`` (fixed mesh, superlu → cg as at Δt = td the system is well
    conditioned). One such step per 1-h outer step is a lower bound on the cost of a
    dynamic run, so the remesh share is an upper bound."""
    td = size_m / 500.0  # Δx/cs
    ov = {**channel_overrides(size_m), "solver.dt": "td", "solver.linear_solver": "cg",
          "lagrangian.enabled": False, "remesh.enabled": False, "run.duration": (4 + n) * td}
    sim = scene_simulation("shear_channel_implicit", ov)
    sim.run(n_steps=1)  # compilation
    sim.run(n_steps=3)  # the ice starts at rest: let the current set it moving
    return timed_run(sim, n_steps=n) / n, sim.dt


def bench_scene(size_m, days):
    dt = 3600.0  # the scene's outer step
    n_steps = int(round(days * DAY / dt))
    sim = scene_simulation("shear_channel", {**channel_overrides(size_m), "solver.velocity_params.speed_m_s": 0.1,
                                             "solver.dt": dt, "run.duration": (n_steps + 1) * dt})
    model = sim.model
    n0 = model.mesh.n_elements
    sim.run(n_steps=1)  # warm-up (numba compile, gmsh start)
    log = model.component("remeshing").log
    first = len(log.events)
    reset_timings(model)
    timed_run(sim, n_steps=n_steps)
    ev = log.events[first:]
    # move: prescribed velocity (the stepper) + mesh motion; remesh: trigger checks + events
    t_move, t_remesh = model.timings["dynamics"] + model.timings["mesh_motion"], model.timings["remeshing"]
    t_solver, dt_td = implicit_step_time(size_m)
    per_event = np.array([e.t_gmsh_s + e.t_remap_s for e in ev]) if ev else np.zeros(1)
    total_dyn = t_move + t_remesh + n_steps * t_solver
    total_td = t_move + t_remesh + days * DAY / dt_td * t_solver
    return {
        "size_m": size_m, "n_elements_start": n0, "n_elements_end": model.mesh.n_elements, "days": days,
        "n_steps": n_steps, "n_events": len(ev), "events_per_day": len(ev) / days,
        "n_global": sum(e.kind == "global" for e in ev),
        "mean_event_s": float(np.mean([e.t_total_s for e in ev])) if ev else 0.0,
        "mean_gmsh_plus_remap_s": float(per_event.mean()),
        "max_event_s": float(max(e.t_total_s for e in ev)) if ev else 0.0,
        "mean_gmsh_s": float(np.mean([e.t_gmsh_s for e in ev])) if ev else 0.0,
        "mean_remap_s": float(np.mean([e.t_remap_s for e in ev])) if ev else 0.0,
        "mean_elements_touched": float(np.mean([e.elements_touched for e in ev])) if ev else 0.0,
        "trigger_check_s_per_step": float(np.mean([e.t_trigger_s for e in ev])) if ev else 0.0,
        "wall_move_s": t_move, "wall_remesh_s": t_remesh,
        "implicit_step_s": t_solver, "implicit_dt_td_s": dt_td,
        "remesh_share_implicit_every_td": t_remesh / total_td,
        "remesh_share_kinematic": t_remesh / (t_move + t_remesh),
        "remesh_share_with_implicit_solver": t_remesh / total_dyn,
        "max_rel_change": float(max((max(abs(v) for v in e.rel_change.values()) if e.rel_change else 0.0)
                                    for e in ev)) if ev else 0.0,
    }


def bench_dynamic(size_m, days):
    """``shear_channel_implicit`` (ocean-driven, dt = 1 h): the measured share of
    remeshing in a real dynamic run."""
    sim = scene_simulation("shear_channel_implicit", {**channel_overrides(size_m), "run.duration": f"{days:g}d"})
    model = sim.model
    n0 = model.mesh.n_elements
    wall = timed_run(sim)
    summ = model.component("remeshing").log.summary()
    tm = model.timings
    return {"size_m": size_m, "n_elements_start": n0, "n_elements_end": model.mesh.n_elements,
            "days": days, "n_events": summ.get("n_events", 0), "events_per_day": summ.get("n_events", 0) / days,
            "wall_s": wall, "solver_s": tm["dynamics"], "move_s": tm["mesh_motion"], "remesh_s": tm["remeshing"],
            "remesh_share": tm["remeshing"] / sum(tm.values()),
            "mean_event_s": summ.get("t_total_s", 0.0) / max(1, summ.get("n_events", 0)),
            "elements_touched": summ.get("elements_touched", 0)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="benchmarks/out/remesh.json")
    ap.add_argument("--dynamic-size", type=float, default=8e3,
                    help="element size [m] of the 10-day ImplicitSolver run (0: skip)")
    args = ap.parse_args()
    res = {"intersect": [], "scene": [], "dynamic": []}
    sizes = [(20_000, 10.0, 1.8e3), (200_000, 6.0, 0.57e3)]
    if args.quick:
        sizes = [(2_000, 6.0, 5.7e3)]
    for n, _days, _size in sizes:
        r = bench_intersect(n)
        res["intersect"].append(r)
        print(f"supermesh {r['n_old']} x {r['n_new']} elements: clip {r['clip_s']:.3f} s, "
              f"celltree {r['celltree_s']:.3f} s ({r['clip_pairs']} / {r['celltree_pairs']} pairs)", flush=True)
    for _n, days, size in sizes:
        r = bench_scene(size, days)
        res["scene"].append(r)
        print(f"shear_channel ~{r['n_elements_start']} elements, {days:g} days: {r['n_events']} events "
              f"({r['events_per_day']:.1f}/day, {r['n_global']} global); per event {r['mean_event_s']:.3f} s "
              f"(gmsh {r['mean_gmsh_s']:.3f} + remap {r['mean_remap_s']:.3f}, max {r['max_event_s']:.3f}), "
              f"{r['mean_elements_touched']:.0f} elements touched; remesh wall {r['wall_remesh_s']:.1f} s vs "
              f"move {r['wall_move_s']:.1f} s; implicit step (dt = td = {r['implicit_dt_td_s']:.1f} s) "
              f"{r['implicit_step_s']:.3f} s -> remesh share of a dynamic run: "
              f"{100 * r['remesh_share_with_implicit_solver']:.1f} % with one implicit step per 1-h outer step "
              f"(upper bound), {100 * r['remesh_share_implicit_every_td']:.3f} % stepping at dt = td",
              flush=True)
    if args.dynamic_size > 0:
        size, days = (14e3, 2.0) if args.quick else (args.dynamic_size, 10.0)
        r = bench_dynamic(size, days)
        res["dynamic"].append(r)
        print(f"shear_channel with ImplicitSolver, ~{r['n_elements_start']} elements, {days:g} days: "
              f"{r['n_events']} events ({r['events_per_day']:.1f}/day), {r['mean_event_s']:.3f} s per event; "
              f"wall {r['wall_s']:.1f} s = solver {r['solver_s']:.1f} + move {r['move_s']:.1f} + remesh "
              f"{r['remesh_s']:.1f} s -> remeshing {100 * r['remesh_share']:.1f} % of the run", flush=True)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(res, indent=1))
    print(f"written {args.out}")


if __name__ == "__main__":
    main()
