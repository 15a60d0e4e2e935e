"""GPU explicit stepper throughput (issue 15): element-sub-steps per second, host
overhead and transfers per outer step, the other components' time, memory per
element on the GPU and on the CPU, and the agreement with the CPU stepper.

Every run is a scene built by the scene builder and run by ``Simulation``: the
``wind_square`` basin (500 km, closed, compact 1 m ice, random cohesion, mesh
motion) at the resolution that gives about ``--elements`` elements, with a
20 m s-1 uniform wind (``--wind uniform``, ramped over 1 min) or moving cyclones
(``--wind cyclones``: the box-with-cyclone set-up) and a 0.1 m s-1 gyre current,
both record fields interpolated on the device; ``solver.device = "cuda"``. The
outer step holds ``--substeps`` sub-steps (default 100) at 0.999 × safety × the
measured stability limit of the mesh, as ``bench_explicit.py``. Two warm-up steps
(compilation, record upload, the initial snapshot) are left out of the figures.

    python benchmarks/bench_gpu.py                                # 200k and 2M elements
    python benchmarks/bench_gpu.py --elements 130000 --mode both --cpu
    python benchmarks/bench_gpu.py --cpu                          # without a GPU: CPU rows only
    NUMBA_ENABLE_CUDASIM=1 python benchmarks/bench_gpu.py --smoke # the script runs (figures meaningless)

Printed per size and launch mode: element-sub-steps/s over the stepper's whole
outer step and over the sub-step loop alone, host+setup overhead and state
transfers per outer step [ms], the rest of the model step (mesh motion) [ms],
device memory per element (the stepper's arrays, and the driver's used-memory
increase), and a byte model of the sub-step loop with the bandwidth it implies.
``--cpu`` adds the CPU stepper on the same scene (serial and parallel kernels):
element-sub-steps/s, its memory per element (persistent arrays and the peak of
one step's temporaries, by tracemalloc), and the largest relative difference of
velocity, stress and damage between the devices after ``--check-steps`` outer
steps from the same initial state. gmsh meshes each size once per process (``--fresh-meshes`` to mesh every build), so
``build_s`` of a later build leaves gmsh out; ``mesh_cache`` in the JSON counts both.
Without a usable GPU the script prints
``NO GPU: ...``, writes ``{"gpu": false, ...}`` (plus the CPU rows with ``--cpu``)
and exits 0.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

L_M = 500e3
OUT = Path("benchmarks/out")


#: bytes of one element-sub-step in the sub-step loop, counting each array the
#: kernels touch once (gathers through the adjacency assumed cached), for an
#: index size of 4 B and n_nodes/n_elements = r (≈ 0.5):
#: element phase: tri 12, b c 48, e_dt γ 16, σ 24 r + 24 w, d 8 r + 8 w, g C σc σT td H 48, velocity gather 16 r;
#: node phase per node: ptr 4, u 16 r + 16 w, Σu 16 r + 16 w, m/Δt 8, f_ext 16, c_d a 8, Uw 16, ½mf 8,
#: fixed 2 (= 142 r-weighted), per adjacency entry (3 per element): element index 4, wb wc 16.
def bytes_per_element_substep(r: float, idx: int = 4) -> float:
    elem = 3 * idx + 48 + 16 + 48 + 16 + 48 + 16 * r
    node = r * (idx + 16 + 16 + 16 + 16 + 8 + 16 + 8 + 16 + 8 + 2)
    adj = 3 * (idx + 16)
    return elem + node + adj


def resolution_for(n_elements: int) -> float:
    """gmsh: elements ≈ 2·1.15·(L/Δx)² (as bench_explicit.py)."""
    return L_M * math.sqrt(2 * 1.15 / n_elements)


def scene_config(n_elements: int, device: str, substeps: int, wind: str, parallel=None):
    from lagice.scenes.config import load_scene

    winds = {"uniform": {"kind": "uniform", "speed_m_s": 20.0, "direction_deg": 0.0, "ramp_s": 60.0},
             "cyclones": {"kind": "cyclones", "n": 4, "background_m_s": [2.0, 0.0]}}
    ov = {"domain.resolution_m": resolution_for(n_elements), "solver.device": device, "solver.substeps": substeps,
          "forcing.wind": winds[wind], "forcing.ocean": {"kind": "gyre", "max_speed_m_s": 0.1},
          "output.every": "1000d", "output.timeseries": None, "output.plot": False, "run.progress": False,
          "run.duration": "2d"}
    if parallel is not None:
        ov["solver.parallel"] = parallel
    return load_scene("wind_square", ov)


def build(n_elements, device, substeps, wind, out_dir, parallel=None, launch=None, tpb=None, max_registers=None):
    """(simulation, seconds to build): the scene, then a Simulation whose outer step holds
    exactly ``substeps`` sub-steps at 0.999 × safety × the stability limit of this mesh."""
    from lagice.scenes.builder import build_simulation
    from lagice.simulation import Simulation
    from lagice.stability import explicit_substep_limit

    t0 = time.perf_counter()
    scene = build_simulation(scene_config(n_elements, device, substeps, wind, parallel), out_dir)
    model = scene.model
    st = model.stepper
    if launch is not None:  # device options the scene file does not carry: set before the first step
        st.launch = launch
    if tpb is not None:
        st.tpb = int(tpb)
    if max_registers:
        st.max_registers = int(max_registers)
    dt = substeps * st.safety * explicit_substep_limit(st.dx_min, st.rheology.E0, st.rheology.params) * 0.999
    sim = Simulation(model, dt=dt, stop=10_000 * dt, progress=False)
    sim.output("1000d", Path(out_dir) / "snapshots", crs=None)  # one snapshot, at the start
    return sim, time.perf_counter() - t0


def timed(sim, steps):
    """Run 2 warm-up steps, then ``steps`` timed ones; returns the figures of the timed ones."""
    model = sim.model
    st = model.stepper
    sim.run(n_steps=2)
    st.kernel_timings = dict.fromkeys(st.kernel_timings, 0.0)
    model.timings = dict.fromkeys(model.timings, 0.0)
    n_sub = [0]
    sim.add_callback(lambda s: n_sub.__setitem__(0, n_sub[0] + s.model.last_report["solver"].iterations),
                     every="1 steps", name="substep_count", needs_host_state=False)
    t0 = time.perf_counter()
    sim.run(n_steps=steps)
    wall = time.perf_counter() - t0
    del sim.activities["substep_count"]
    m = model.mesh.n_elements
    es = m * n_sub[0]
    dyn = model.timings["dynamics"]
    return {"n_elements": m, "n_nodes": model.mesh.n_nodes, "outer_steps": steps,
            "substeps_per_step": n_sub[0] / steps, "outer_step_s": sim.dt,
            "element_substeps_per_s_stepper": es / dyn, "element_substeps_per_s_wall": es / wall,
            "kernel_timings_ms_per_step": {k: 1e3 * v / steps for k, v in st.kernel_timings.items()},
            "component_ms_per_step": {k: 1e3 * v / steps for k, v in model.timings.items()},
            "wall_ms_per_step": 1e3 * wall / steps, "mean_damage": float(np.mean(model.state.damage)), "es": es}


def bench_gpu(n, mode, a, tpb, regs=0):
    from numba import cuda

    from lagice.solvers.cuda_explicit import simulator_enabled

    sim_mode = simulator_enabled()
    free0 = None if sim_mode else cuda.current_context().get_memory_info()[0]
    sim, build_s = build(n, "cuda", a.substeps, a.wind, a.out / f"gpu_{n}_{mode}_{tpb}_{regs}", launch=mode,
                         tpb=tpb, max_registers=regs)
    row = timed(sim, a.steps)
    st = sim.model.stepper
    used = None if sim_mode else free0 - cuda.current_context().get_memory_info()[0]
    m = row["n_elements"]
    kt = st.kernel_timings
    r = row["n_nodes"] / m
    bpe = bytes_per_element_substep(r, 4 if st._index_dtype == np.int32 else 8)
    loop_s = kt["substeps"]
    row.update(device="cuda", launch=st.launch_used, launch_note=st.launch_note, threads_per_block=st.tpb,
               max_registers=st.max_registers,
               forcing_paths=st.forcing_paths, build_s=build_s,
               substep_loop_per_s=row["es"] / loop_s if loop_s > 0 else None,
               overhead_ms_per_step=row["kernel_timings_ms_per_step"]["forcing"]
               + row["kernel_timings_ms_per_step"]["setup"],
               transfer_ms_per_step=row["kernel_timings_ms_per_step"]["transfer"],
               device_bytes_per_element=st.device_bytes() / m,
               driver_bytes_per_element=None if used is None else used / m,
               model_bytes_per_element_substep=bpe,
               achieved_GB_s=bpe * row["es"] / loop_s / 1e9 if loop_s > 0 else None)
    return row


def cpu_bytes(sim):
    """Bytes the CPU run keeps: the state's checkpointed fields, the mesh and its
    adjacency, and the arrays the stepper holds between steps (not the forcing)."""
    from lagice.fields import checkpoint_arrays

    model = sim.model
    st = model.stepper
    mesh = model.mesh
    arrays = list(checkpoint_arrays(model.state).values()) + [mesh.nodes, mesh.triangles, *mesh.node_elements]
    for obj in (st, getattr(st, "nodes", None)):
        if obj is not None:
            arrays += [v for v in vars(obj).values() if isinstance(v, np.ndarray)]
    return sum(a.nbytes for a in arrays)


def bench_cpu(n, parallel, a):
    sim, build_s = build(n, "cpu", a.substeps, a.wind, a.out / f"cpu_{n}_{parallel}", parallel=parallel)
    row = timed(sim, max(1, a.steps // 2))
    m = row["n_elements"]
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    sim.run(n_steps=1)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    row.update(device="cpu", parallel=parallel, build_s=build_s, persistent_bytes_per_element=cpu_bytes(sim) / m,
               step_peak_bytes_per_element=peak / m)
    return row


def agreement(n, a):
    """Largest relative differences CPU vs GPU after ``--check-steps`` outer steps of the
    same scene from the same initial state."""
    out = {}
    sims = {dev: build(n, dev, a.substeps, a.wind, a.out / f"check_{dev}_{n}")[0] for dev in ("cpu", "cuda")}
    for s in sims.values():
        s.run(n_steps=a.check_steps)
    x, y = sims["cpu"].model.state, sims["cuda"].model.state
    for k in ("velocity", "stress", "damage"):
        u, v = getattr(x, k), getattr(y, k)
        out[f"max_rel_diff_{k}"] = float(np.abs(u - v).max() / max(np.abs(u).max(), 1e-300))
    out["agreement_outer_steps"] = a.check_steps
    return out


def scene_days(n, device, a):
    """The scene itself for ``--days`` simulated days (item 5): its own outer step
    (600 s) and automatic sub-step count, mesh motion and remeshing, one snapshot at
    the start; wall time, its split by component, sub-steps and remesh events."""
    from lagice.scenes.builder import build_simulation

    cfg = scene_config(n, device, None, a.wind)
    cfg["run"]["duration"] = f"{a.days * 24:g}h"
    cfg["run"]["progress"] = not a.smoke  # progress lines: a long run shows where it is
    t0 = time.perf_counter()
    sim = build_simulation(cfg, a.out / f"days_{device}_{n}")
    build_s = time.perf_counter() - t0
    model = sim.model
    n_sub = [0]
    sim.add_callback(lambda s: n_sub.__setitem__(0, n_sub[0] + s.model.last_report["solver"].iterations),
                     every="1 steps", name="substep_count", needs_host_state=False)
    t0 = time.perf_counter()
    summ = sim.run()
    wall = time.perf_counter() - t0
    m = model.mesh.n_elements
    return {"device": device, "n_elements": m, "days": a.days, "build_s": build_s, "wall_s": wall,
            "finished": summ["finished"], "outer_steps": summ["steps"], "substeps": n_sub[0],
            "element_substeps_per_s_wall": m * n_sub[0] / wall, "remesh_count": summ["remesh_count"],
            "component_s": dict(summ["timings"]), "mean_damage": float(np.mean(model.state.damage))}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[200_000, 2_000_000])
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--substeps", type=int, default=100)
    ap.add_argument("--wind", choices=["uniform", "cyclones"], default="uniform")
    ap.add_argument("--mode", choices=["auto", "cooperative", "launches", "both"], default="both")
    ap.add_argument("--threads-per-block", type=int, nargs="+", default=[128],
                    help="CUDA block size(s); each is timed for every size and launch mode")
    ap.add_argument("--max-registers", type=int, nargs="+", default=[0],
                    help="register cap(s) per thread of the cooperative kernel (0: none); each is timed")
    ap.add_argument("--fresh-meshes", action="store_true",
                    help="run gmsh for every build (default: once per size, scene_runs.reuse_gmsh_meshes)")
    ap.add_argument("--cpu", action="store_true", help="also time the CPU stepper and check agreement")
    ap.add_argument("--check-steps", type=int, default=3)
    ap.add_argument("--smoke", action="store_true", help="tiny sizes (for the CUDA simulator)")
    ap.add_argument("--days", type=float, default=0.0,
                    help="also run the scene for this many simulated days at the first --elements size "
                         "(its own 600 s step and sub-step count) on the GPU")
    ap.add_argument("--days-cpu", action="store_true", help="the --days run on the CPU as well")
    ap.add_argument("--out", type=Path, default=OUT / "gpu_runs", help="scratch folder of the runs")
    ap.add_argument("--json", type=Path, default=OUT / "gpu.json")
    a = ap.parse_args(argv)

    from lagice.solvers.cuda_explicit import cuda_status, simulator_enabled

    ok, info = cuda_status()
    a.json.parent.mkdir(parents=True, exist_ok=True)
    if simulator_enabled():
        print("SIMULATOR (NUMBA_ENABLE_CUDASIM=1): kernels run as Python threads; the figures below only "
              "show that the script runs and mean nothing about a GPU.")
        a.smoke = True
    if a.smoke:
        a.elements, a.steps, a.substeps, a.check_steps = [150], 1, 3, 1
        a.days = min(a.days, 1 / 24)
    report = {"gpu": ok, "device": info, "simulator": simulator_enabled(), "rows": []}
    if not a.fresh_meshes:
        from scene_runs import reuse_gmsh_meshes

        report["mesh_cache"] = reuse_gmsh_meshes()  # updated in place as builds run
    if not ok:
        print(f"NO GPU: {info}.\n"
              "No GPU figure was measured. Run this on a machine with an NVIDIA GPU (docs/gpu.md).")
        report["reason"] = info
    else:
        import numba

        print(f"device: {info}; numba {numba.__version__}")
        modes = ["cooperative", "launches"] if a.mode == "both" else [a.mode]
        print(f"{'elements':>9} {'launch':>11} {'tpb':>4} {'regs':>4} {'sub/step':>8} {'Gel-sub/s':>10} "
              f"{'loop G/s':>9} {'setup ms':>9} {'xfer ms':>8} {'other ms':>9} {'B/elem':>7} {'GB/s':>7}")
        for n in a.elements:
            combos = [(m, t, g) for m in modes for t in a.threads_per_block
                      for g in (a.max_registers if m == "cooperative" else [0])]
            for mode, tpb, regs in combos:
                r = bench_gpu(n, mode, a, tpb, regs)
                report["rows"].append(r)
                other = sum(v for k, v in r["component_ms_per_step"].items() if k != "dynamics")
                loop = (r["substep_loop_per_s"] or 0.0) / 1e9
                print(f"{r['n_elements']:>9} {r['launch']:>11} {r['threads_per_block']:>4} "
                      f"{r['max_registers'] or '-':>4} "
                      f"{r['substeps_per_step']:>8.0f} "
                      f"{r['element_substeps_per_s_stepper'] / 1e9:>10.3f} {loop:>9.3f} "
                      f"{r['overhead_ms_per_step']:>9.2f} {r['transfer_ms_per_step']:>8.2f} {other:>9.2f} "
                      f"{r['device_bytes_per_element']:>7.0f} {r['achieved_GB_s'] or 0:>7.0f}", flush=True)
                if r["launch_note"]:
                    print(f"  note: {r['launch_note']}")
                if r["driver_bytes_per_element"] is not None:
                    print(f"  driver used-memory increase: {r['driver_bytes_per_element']:.0f} B/element")
            if a.cpu:
                agr = agreement(n, a)
                report["rows"][-1].update(agr)
                print(f"  GPU vs CPU after {agr['agreement_outer_steps']} outer steps: max rel diff velocity "
                      f"{agr['max_rel_diff_velocity']:.2e}, stress {agr['max_rel_diff_stress']:.2e}, damage "
                      f"{agr['max_rel_diff_damage']:.2e}")
    if a.cpu:
        print(f"{'elements':>9} {'CPU':>9} {'sub/step':>8} {'Mel-sub/s':>10} {'other ms':>9} "
              f"{'B/elem kept':>11} {'B/elem step peak':>16}")
        for n in a.elements:
            for par in (False, True):
                r = bench_cpu(n, par, a)
                report["rows"].append(r)
                other = sum(v for k, v in r["component_ms_per_step"].items() if k != "dynamics")
                print(f"{r['n_elements']:>9} {'parallel' if par else 'serial':>9} {r['substeps_per_step']:>8.0f} "
                      f"{r['element_substeps_per_s_stepper'] / 1e6:>10.1f} {other:>9.2f} "
                      f"{r['persistent_bytes_per_element']:>11.0f} {r['step_peak_bytes_per_element']:>16.0f}",
                      flush=True)
    if a.days > 0:
        report["days_runs"] = []
        for dev in (["cuda"] if ok else []) + (["cpu"] if a.days_cpu else []):
            r = scene_days(a.elements[0], dev, a)
            report["days_runs"].append(r)
            comp = ", ".join(f"{k} {v:.1f}" for k, v in r["component_s"].items() if v > 0.05)
            print(f"{a.days:g} days on {dev}, {r['n_elements']} elements: {r['wall_s']:.1f} s wall "
                  f"(build {r['build_s']:.1f} s), {r['outer_steps']} steps, {r['substeps']} sub-steps, "
                  f"{r['element_substeps_per_s_wall'] / 1e9:.3f} G element-sub-steps/s over the wall time, "
                  f"{r['remesh_count']} remeshes; components [s]: {comp}", flush=True)
    a.json.write_text(json.dumps(report, indent=1, default=str))
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
