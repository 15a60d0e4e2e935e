"""GPU explicit stepper throughput (issue 15): element-sub-steps per second,
host overhead per outer step, state transfer cost, memory per element, and
agreement with the CPU solver on the same problem.

The problem is the ``wind_square`` set-up on a structured mesh (a jittered
right-triangle grid of a 500 km closed basin, nodes and elements numbered
row by row, so that 2M elements need no gmsh run): compact 1 m ice, random
cohesion, a 20 m s-1 uniform wind and a 0.1 m s-1 gyre current as record
fields (interpolated on the device), ocean drag, Coriolis at 75° N; the clock
starts at 12 h (full wind: damage is active). Each outer step holds
``--substeps`` sub-steps (default 100) at 0.999 × safety × the measured
stability limit, as ``bench_explicit.py``.

    python benchmarks/bench_gpu.py                                # 200k and 2M elements
    python benchmarks/bench_gpu.py --elements 50000 200000 2000000 --mode both --cpu
    NUMBA_ENABLE_CUDASIM=1 python benchmarks/bench_gpu.py --smoke # the script runs (figures meaningless)

Printed per size and launch mode: element-sub-steps/s over whole outer steps
and over the sub-step loop alone, host+setup overhead per outer step, the
cost of one full state sync (``to_host`` + ``from_host``: what
``sync="step"`` pays per step), device memory per element (our arrays, and
the driver's used-memory increase), a byte model of the sub-step loop with the
achieved bandwidth. ``--cpu`` adds the CPU ExplicitSolver on the same mesh
(serial and parallel kernels) and the largest relative difference of
velocity, stress and damage between the two devices after ``--check-steps``
outer steps from the same state. Without a usable GPU the script says so,
writes ``{"gpu": false, ...}`` and exits 0.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

L_M = 500e3
HOUR = 3600.0

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


def structured_mesh(n_elements: int, seed: int = 0):
    """Jittered right-triangle mesh of the L_M square with about ``n_elements``
    elements, every boundary edge tagged coast (no-slip)."""
    from lagice.mesh import Mesh
    from lagice.mesh.core import boundary_edges_of

    k = max(2, round(math.sqrt(n_elements / 2.0)))
    dx = L_M / k
    x = np.linspace(0.0, L_M, k + 1)
    X, Y = np.meshgrid(x, x)
    nodes = np.c_[X.ravel(), Y.ravel()]
    rng = np.random.default_rng(seed)
    inner = (nodes[:, 0] > 0) & (nodes[:, 0] < L_M) & (nodes[:, 1] > 0) & (nodes[:, 1] < L_M)
    nodes[inner] += rng.uniform(-0.15 * dx, 0.15 * dx, (int(inner.sum()), 2))
    j, i = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    n0 = (j * (k + 1) + i).ravel()
    n1, n2, n3 = n0 + 1, n0 + k + 1, n0 + k + 2
    tri = np.empty((2 * k * k, 3), np.int64)
    tri[0::2] = np.c_[n0, n1, n3]
    tri[1::2] = np.c_[n0, n3, n2]
    edges = boundary_edges_of(tri)
    return Mesh(nodes, tri, edges, np.zeros(len(edges), np.int32), ("coast",)), dx


def problem(n_elements: int, seed: int = 0):
    from forcing.records import RegularGrid
    from forcing.synthetic import gyre_current, uniform_wind
    from lagice.forces import Coriolis, OceanDrag, WindStress
    from lagice.params import DragParams, MaxwellEBParams
    from lagice.rheology import MaxwellEB, draw_cohesion
    from lagice.state import IceState

    mesh, dx = structured_mesh(n_elements, seed)
    grid = RegularGrid.from_bbox(0.0, L_M, 0.0, L_M, 25e3, margin_m=100e3)
    wind = uniform_wind(grid, 4 * 86400.0, speed_m_s=20.0, direction_deg=0.0, ramp_s=HOUR)
    current = gyre_current(grid, 0.1)
    drag = DragParams()
    forces = [WindStress(wind, rho_air=drag.rho_air, drag=drag.air_drag),
              OceanDrag(current, rho_water=drag.rho_water, drag=drag.water_drag,
                        turning_angle_deg=drag.turning_angle_deg),
              Coriolis(latitude_deg=75.0)]
    params = MaxwellEBParams()
    rheo = MaxwellEB(params)
    state = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0,
                             cohesion_pa=draw_cohesion(mesh.n_elements, params, np.random.default_rng(seed)))
    state.time_s = 12 * HOUR
    return mesh, state, rheo, forces, dx


def copy_state(st):
    from lagice.state import IceState

    return IceState(mesh=st.mesh, velocity=st.velocity.copy(), thickness=st.thickness.copy(),
                    concentration=st.concentration.copy(), damage=st.damage.copy(), stress=st.stress.copy(),
                    cohesion=st.cohesion.copy(), time_s=st.time_s, step=st.step)


def outer_step(solver, substeps):
    from lagice.stability import explicit_substep_limit

    lim = explicit_substep_limit(solver.dx_min, solver.rheology.E0)
    return substeps * solver.safety * lim * 0.999


def bench_gpu(n, mode, steps, substeps, cpu, check_steps, tpb):
    from numba import cuda

    from lagice.solvers.cuda_explicit import CudaExplicitSolver, simulator_enabled

    mesh, st, rheo, forces, dx = problem(n)
    st0 = copy_state(st)
    sim = simulator_enabled()
    free0 = None if sim else cuda.current_context().get_memory_info()[0]
    s = CudaExplicitSolver(rheo, mesh, forces=forces, substeps=substeps, sync="explicit", launch=mode,
                           threads_per_block=tpb)
    dt = outer_step(s, substeps)
    t_c = time.perf_counter()
    for _ in range(2):  # compilation, record upload
        s.step(st, dt)
    compile_s = time.perf_counter() - t_c
    used = None if sim else free0 - cuda.current_context().get_memory_info()[0]
    s.kernel_timings = {k: 0.0 for k in s.kernel_timings}
    t0 = time.perf_counter()
    n_sub = 0
    for _ in range(steps):
        n_sub += s.step(st, dt).iterations
    wall = time.perf_counter() - t0
    kt = s.kernel_timings
    t1 = time.perf_counter()
    s.to_host(st)
    t2 = time.perf_counter()
    s.from_host(st)
    t3 = time.perf_counter()
    m = mesh.n_elements
    es = m * n_sub
    r = mesh.n_nodes / m
    bpe = bytes_per_element_substep(r, 4 if s._index_dtype == np.int32 else 8)
    row = {"n_elements": m, "n_nodes": mesh.n_nodes, "dx_m": dx, "launch": s.launch_used,
           "launch_note": s.launch_note, "threads_per_block": tpb, "outer_steps": steps,
           "substeps_per_step": n_sub / steps, "outer_step_s": dt,
           "element_substeps_per_s": es / wall, "substep_loop_per_s": es / kt["substeps"],
           "overhead_ms_per_outer_step": 1e3 * (kt["forcing"] + kt["setup"]) / steps,
           "to_host_ms": 1e3 * (t2 - t1), "from_host_ms": 1e3 * (t3 - t2),
           "device_bytes_per_element": s.device_bytes() / m,
           "driver_bytes_per_element": None if used is None else used / m,
           "model_bytes_per_element_substep": bpe,
           "achieved_GB_s": bpe * es / kt["substeps"] / 1e9, "compile_and_warmup_s": compile_s,
           "mean_damage": float(np.mean(st.damage)), "forcing_paths": s.forcing_paths, "wall_s": wall}
    if cpu:
        row.update(bench_cpu(n, substeps, dt, max(1, steps // 2)))
        row.update(agreement(st0, s, dt, check_steps))
    return row


def bench_cpu(n, substeps, dt, steps):
    """CPU ExplicitSolver, serial and parallel kernels, same problem."""
    from lagice.solvers import ExplicitSolver

    out = {}
    for par in (False, True):
        mesh, st, rheo, forces, _ = problem(n)
        s = ExplicitSolver(rheo, mesh, forces=forces, substeps=substeps, parallel=par)
        s.step(st, dt)  # compile
        t0 = time.perf_counter()
        n_sub = sum(s.step(st, dt).iterations for _ in range(steps))
        out[f"cpu_{'parallel' if par else 'serial'}_element_substeps_per_s"] = mesh.n_elements * n_sub / (
            time.perf_counter() - t0)
    return out


def agreement(st0, gpu_solver, dt, steps):
    """Largest relative differences CPU vs GPU after ``steps`` outer steps from ``st0``."""
    from lagice.solvers import ExplicitSolver
    from lagice.solvers.cuda_explicit import CudaExplicitSolver

    mesh = st0.mesh
    rheo, forces = gpu_solver.rheology, gpu_solver.forces
    a, b = copy_state(st0), copy_state(st0)
    cpu = ExplicitSolver(rheo, mesh, forces=forces, substeps=gpu_solver.substeps)
    dev = CudaExplicitSolver(rheo, mesh, forces=forces, substeps=gpu_solver.substeps, launch=gpu_solver.launch_used,
                             threads_per_block=gpu_solver.tpb)
    for _ in range(steps):
        cpu.step(a, dt)
        dev.step(b, dt)
    out = {}
    for k in ("velocity", "stress", "damage"):
        x, y = getattr(a, k), getattr(b, k)
        out[f"max_rel_diff_{k}"] = float(np.abs(x - y).max() / max(np.abs(x).max(), 1e-300))
    out["max_rel_diff_mean_velocity"] = float(np.abs(cpu.mean_velocity - dev.mean_velocity).max()
                                              / np.abs(cpu.mean_velocity).max())
    out["agreement_outer_steps"] = steps
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[200_000, 2_000_000])
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--substeps", type=int, default=100)
    ap.add_argument("--mode", choices=["auto", "cooperative", "launches", "both"], default="both")
    ap.add_argument("--threads-per-block", type=int, default=128)
    ap.add_argument("--cpu", action="store_true", help="also time the CPU solver and check agreement")
    ap.add_argument("--check-steps", type=int, default=3)
    ap.add_argument("--smoke", action="store_true", help="tiny sizes (for the CUDA simulator)")
    ap.add_argument("--json", type=Path, default=Path("benchmarks/out/gpu.json"))
    a = ap.parse_args(argv)

    from lagice.solvers.cuda_explicit import cuda_status, simulator_enabled

    ok, info = cuda_status()
    a.json.parent.mkdir(parents=True, exist_ok=True)
    if not ok:
        print(f"NO GPU: numba.cuda.is_available() is False ({info}).\n"
              "Nothing was measured. Run this on a machine with an NVIDIA GPU (docs/gpu.md).")
        a.json.write_text(json.dumps({"gpu": False, "reason": info}, indent=1))
        return 0
    if simulator_enabled():
        print("SIMULATOR (NUMBA_ENABLE_CUDASIM=1): kernels run as Python threads; the figures below only "
              "show that the script runs and mean nothing about a GPU.")
        if not a.smoke:
            print("(forcing --smoke sizes)")
        a.elements, a.steps, a.substeps, a.check_steps = [400], 1, 3, 1
    elif a.smoke:
        a.elements, a.steps, a.substeps = [2000], 2, 10
    import numba

    print(f"device: {info}; numba {numba.__version__}")
    modes = ["cooperative", "launches"] if a.mode == "both" else [a.mode]
    print(f"{'elements':>9} {'launch':>11} {'sub/step':>8} {'Gel-sub/s':>10} {'loop G/s':>9} "
          f"{'overhead ms':>11} {'sync ms':>8} {'B/elem':>7} {'GB/s':>7}")
    rows = []
    for n in a.elements:
        for mode in modes:
            r = bench_gpu(n, mode, a.steps, a.substeps, a.cpu and mode == modes[0], a.check_steps,
                          a.threads_per_block)
            rows.append(r)
            print(f"{r['n_elements']:>9} {r['launch']:>11} {r['substeps_per_step']:>8.0f} "
                  f"{r['element_substeps_per_s'] / 1e9:>10.3f} {r['substep_loop_per_s'] / 1e9:>9.3f} "
                  f"{r['overhead_ms_per_outer_step']:>11.2f} {r['to_host_ms'] + r['from_host_ms']:>8.2f} "
                  f"{r['device_bytes_per_element']:>7.0f} {r['achieved_GB_s']:>7.0f}", flush=True)
            if r["launch_note"]:
                print(f"  note: {r['launch_note']}")
            if "cpu_serial_element_substeps_per_s" in r:
                print(f"  CPU same mesh: serial {r['cpu_serial_element_substeps_per_s'] / 1e6:.1f} M/s, "
                      f"parallel {r['cpu_parallel_element_substeps_per_s'] / 1e6:.1f} M/s; "
                      f"GPU vs CPU after {r['agreement_outer_steps']} outer steps: max rel diff velocity "
                      f"{r['max_rel_diff_velocity']:.2e}, stress {r['max_rel_diff_stress']:.2e}, damage "
                      f"{r['max_rel_diff_damage']:.2e}, mean velocity {r['max_rel_diff_mean_velocity']:.2e}")
    a.json.write_text(json.dumps({"gpu": True, "device": info, "simulator": simulator_enabled(), "rows": rows},
                                 indent=1, default=str))
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
