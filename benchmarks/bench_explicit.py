"""Explicit solver throughput (issue 3): element-sub-steps per second, by kernel.

Runs the ``wind_square`` scene (scene builder + Simulation, the path of ``lagice run``)
at resolutions giving about 10k, 50k and 200k elements, with a fixed mesh
(``lagrangian.enabled = false``: the solver alone is timed) and the wind at full
strength from the start (``forcing.wind.params.ramp_h = 0``) so that damage is
active. Each outer step holds 100 sub-steps at 0.7 × the measured stability limit
(``solver.substeps``, ``solver.dt`` from the mesh's smallest element). Two warm-up
steps (numba compilation) are run first, then the kernel timings are reset and a
few outer steps are timed with ``sim.run``. Printed: element-sub-steps per second
overall (wall time of the time loop, NaN checker included) and per kernel
(node_velocity: internal-force gather + semi-implicit momentum;
element_stress_damage: strain rate + Maxwell stress + damage/healing, from the
stepper's ``kernel_timings``), plus the per-outer-step overhead (forcing
evaluation, lumped mass, adjacency weights).

Roofline figures: the bytes the two kernels move per element-sub-step are counted
from the arrays they read and write (:func:`kernel_bytes`: every array each kernel
streams through once per sub-step, read-modify-write arrays twice; gathered arrays
(σ in the node kernel, u in the element kernel) once, i.e. assuming the gather
hits cache; arrays touched only at damaging or prescribed entities are left out),
so achieved GB/s = bytes × element-sub-steps/s. A STREAM triad (a = b + s c, numba,
serial and parallel, arrays of 2 × 10⁷ float64 ≫ cache, 24 B per entry counted as
STREAM does) is measured in the same run for the bandwidth the machine delivers now,
before and after the kernels; the table gives the fraction of the first, the summary after it
the fraction of the better of the two (on shared hosts the triad moves by up to 2x between runs).
Each configuration is timed ``--repeat`` times (fresh simulation each) and the best
is kept (the machine is shared: the best run is the least disturbed). The JSON also
has the throughput per CPU second of the process (``element_substeps_per_cpu_s``):
for the serial kernels, what an undisturbed core would give.

    python benchmarks/bench_explicit.py                      # 10k, 50k
    python benchmarks/bench_explicit.py --elements 10000 50000 200000 --parallel all
    NUMBA_NUM_THREADS=2 python benchmarks/bench_explicit.py --elements 50000
    python benchmarks/bench_explicit.py --quick              # 10k, serial, 2 timed steps
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit, prange
from scene_runs import reset_timings, reuse_gmsh_meshes, scene_dx_min, scene_simulation, timed_run

from lagice.params import MaxwellEBParams
from lagice.stability import explicit_substep_limit

DOMAIN_M = 500e3  # the wind_square basin
SAFETY = 0.7
WARMUP_STEPS = 2


def resolution_for(n_elements, domain_m=DOMAIN_M):
    """gmsh: elements ≈ 2.3 (L/Δx)²."""
    return domain_m * math.sqrt(2 * 1.15 / n_elements)


TRIAD_N = 20_000_000


def _triad(a, b, c, s):
    for i in prange(a.shape[0]):
        a[i] = b[i] + s * c[i]


triad_serial = njit(_triad)
triad_parallel = njit(parallel=True)(_triad)


def stream_triad(parallel: bool, n: int = TRIAD_N, repeats: int = 10) -> float:
    """Best STREAM-triad bandwidth [GB/s] (24 B per entry: 2 reads, 1 write)."""
    b = np.random.default_rng(0).random(n)
    c = np.random.default_rng(1).random(n)
    a = np.empty(n)
    f = triad_parallel if parallel else triad_serial
    f(a, b, c, 3.0)
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        f(a, b, c, 3.0)
        best = min(best, time.perf_counter() - t0)
    return 24.0 * n / best / 1e9


def kernel_bytes(st, mesh) -> dict:
    """Bytes per element-sub-step the node and element kernels move (module doc), from
    the stepper's own arrays (int32 connectivity as the kernels get it)."""
    n, m = mesh.n_nodes, mesh.n_elements
    ptr, elems, tri = st._indices(mesh) if hasattr(st, "_indices") else (*mesh.node_elements[:2], mesh.triangles)
    f8 = 8
    node = (ptr.nbytes + elems.nbytes + 2 * len(elems) * f8   # adjacency: ptr, elems, w (wb, wc)
            + n * (2 * f8 * 2 * 2                                # vel, vel_sum: read + write
                   + 8 * f8)                                     # nc: m_dt, cda, half_mf, fext, current, pad
            + n * 2                                              # fixed (int8)
            + m * 3 * f8)                                        # sigma gathered (read once)
    elem = (tri.nbytes + 2 * m * 3 * f8                          # tri, b, c
            + n * 2 * f8                                         # vel gathered (read once)
            + m * 3 * f8 * 2                                     # sigma read + write
            + m * f8 * 6)                                        # damage, cohesion, td, heal, e_dt, gamma
    return {"node_bytes": node / m, "element_bytes": elem / m, "total_bytes": (node + elem) / m,
            "index_bytes": (ptr.nbytes + elems.nbytes + tri.nbytes) / m}


def element_kernel_rates(n_target: int = 50_000, reps: int = 20) -> dict:
    """The serial element kernel alone on a Morton-ordered square mesh, per CPU second
    [elements/s]: without damage (huge cohesion, no healing), with healing acting on
    damaged elements (moduli refreshed every sub-step) and with every element damaging
    (``_dcrit`` and the damage step everywhere): where the kernel's time goes."""
    import shapely

    from lagice.fem import shape_gradients
    from lagice.mesh import generate_mesh, renumber_for_locality
    from lagice.rheology import MaxwellEB
    from lagice.solvers.explicit import element_kernels, envelope_factors

    rheo = MaxwellEB()
    p = rheo.params
    kernel = element_kernels(float(p.alpha))[0]  # the serial build a run with this α uses
    mesh = renumber_for_locality(generate_mesh(shapely.box(0, 0, DOMAIN_M, DOMAIN_M), resolution_for(n_target)))[0]
    m, n = mesh.n_elements, mesh.n_nodes
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
    tri = mesh.triangles.astype(np.int32)
    rng = np.random.default_rng(0)
    vel = rng.normal(0, 0.1, (n, 2))
    out = {"n_elements": m}
    for name, coh, heal, d0 in (("no damage", 1e12, 0.0, 0.0), ("healing damaged ice", 1e12, 1e-6, 0.5),
                                ("all damaging", 1e3, 1e-6, 0.5)):
        sigma = rng.normal(0, 1e4, (m, 3))
        damage = np.full(m, d0)
        cohv = np.full(m, coh)
        kc, kt = envelope_factors(rheo)
        args = (tri, b, c, vel, sigma, damage, np.ones(m), cohv, kc, kt, np.full(m, 20.0),
                np.full(m, heal), np.full(m, 4.0 * p.E0), np.full(m, 0.99), None, None, None, None, None, None,
                4.0, 1.1,
                0.3, 0.7,
                rheo.q, rheo._denom, p.max_damage, p.E0, p.relaxation_time_s, float(p.alpha), np.zeros(m, np.int8),
                None)
        kernel(*args)
        t0 = time.process_time()
        for _ in range(reps):
            kernel(*args)
        out[name] = m * reps / (time.process_time() - t0)
    return out


def bench(n_target, steps, parallel, substeps, profile_kernels=False, extra=None):
    res = resolution_for(n_target)
    ov = {"domain.resolution_m": res, "lagrangian.enabled": False, "forcing.wind.params.ramp_h": 0.0,
          "solver.substeps": substeps, "output.timeseries": None, **(extra or {})}
    if parallel is not None:
        ov["solver.parallel"] = parallel
    # the outer step: `substeps` sub-steps at SAFETY × the stability limit of undamaged ice
    lim = explicit_substep_limit(scene_dx_min("wind_square", ov), MaxwellEBParams().E0)
    dt = round(substeps * SAFETY * lim * 0.999, 6)
    n = WARMUP_STEPS + steps
    sim = scene_simulation("wind_square", {**ov, "solver.dt": dt, "run.duration": n * dt})
    model = sim.model
    st = model.stepper
    if profile_kernels:
        st.profile_kernels = True
    sim.run(n_steps=WARMUP_STEPS)  # numba compilation, damage starts
    reset_timings(model)
    sub0 = model.last_report["solver"].iterations
    cpu0 = time.process_time()
    wall = timed_run(sim)
    cpu = time.process_time() - cpu0
    m = model.mesh.n_elements
    es = m * substeps * steps
    kt = st.kernel_timings
    choice = getattr(st, "kernel_choice", None) or {}
    par = choice.get("parallel", st.nodes.parallel_for(model.mesh))
    nb = kernel_bytes(st, model.mesh)
    sub_s = kt.get("substeps", 0.0) or (kt["node_velocity"] + kt["element_stress_damage"])
    return {"n_elements": m, "n_nodes": model.mesh.n_nodes, "resolution_m": res,
            "parallel": par, "threads": choice.get("threads", numba.get_num_threads() if par else 1),
            "choice": choice.get("method", "fixed rule"), **nb,
            "substep_loop_per_s": es / sub_s,
            "achieved_GB_s": nb["total_bytes"] * es / sub_s / 1e9,
            "outer_steps": steps, "substeps_per_step": float(sub0),
            "element_substeps_per_s": es / wall,
            # CPU time of the process (all its threads): for serial kernels the throughput a
            # quiet core would give, much less sensitive to other jobs than the wall time
            "element_substeps_per_cpu_s": es / cpu, "cpu_s": cpu,
            "node_velocity_per_s": es / kt["node_velocity"] if kt.get("node_velocity") else math.nan,
            "element_stress_damage_per_s": (es / kt["element_stress_damage"] if kt.get("element_stress_damage")
                                            else math.nan),
            "overhead_ms_per_outer_step": 1e3 * (kt["forcing"] + kt["setup"]) / steps,
            "loop_overhead_ms_per_outer_step": 1e3 * (wall - model.timings["dynamics"]) / steps,
            "mean_damage": float(np.mean(model.state.damage)),
            "wall_s": wall}


def _mode(r: dict) -> str:
    """The table's mode column: requested:used, e.g. ``aut:par2`` or ``no:ser``."""
    return f"{r['requested'][:3]}:{'par' + str(r['threads']) if r['parallel'] else 'ser'}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[10_000, 50_000])
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--substeps", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=3, help="runs per configuration; the best is kept")
    ap.add_argument("--parallel", choices=["auto", "yes", "no", "both", "all"], default="both",
                    help="both: serial and parallel; all: serial, parallel and auto (measured choice)")
    ap.add_argument("--profile-kernels", action="store_true",
                    help="time node and element kernels separately (Python loop over the sub-steps)")
    ap.add_argument("--quick", action="store_true", help="10k elements, serial kernels, 2 timed steps")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scene override as `lagice run --set` (e.g. domain.renumber=false)")
    ap.add_argument("--fresh-meshes", action="store_true",
                    help="run gmsh for every build (default: once per size, scene_runs.reuse_gmsh_meshes)")
    ap.add_argument("--json", type=Path, default=Path(__file__).resolve().parent / Path("out/explicit.json"))
    a = ap.parse_args(argv)
    from lagice.scenes.config import _split

    if not a.fresh_meshes:  # the repeats and the stability limit mesh each size once
        reuse_gmsh_meshes()

    extra = dict(_split(kv) for kv in a.set)
    if a.quick:
        a.elements, a.parallel, a.steps, a.repeat = [10_000], "no", 2, 1
    modes = {"auto": [None], "yes": [True], "no": [False], "both": [False, True],
             "all": [False, True, None]}[a.parallel]
    print(f"numba threads: {numba.get_num_threads()}  (threading layer set on first parallel call)")
    triad = {"serial": stream_triad(False), "parallel": stream_triad(True)}
    print(f"STREAM triad (numba, {TRIAD_N:.0e} float64 per array): serial {triad['serial']:.2f} GB/s, "
          f"parallel ({numba.get_num_threads()} threads) {triad['parallel']:.2f} GB/s", flush=True)
    ek = element_kernel_rates()
    print(f"element kernel alone (serial, {ek['n_elements']} elements, per CPU second): "
          + ", ".join(f"{k} {v / 1e6:.1f} M/s" for k, v in ek.items() if k != "n_elements"), flush=True)
    print(f"{'elements':>9} {'mode':>12} {'sub/step':>8} {'Mel-sub/s':>10} {'loop':>8} {'node':>8} {'element':>8} "
          f"{'B/el-sub':>8} {'GB/s':>6} {'%triad':>6} {'overhead ms/step':>16} {'loop ms/step':>12}")
    rows = []
    for n in a.elements:
        for par in modes:
            best = None
            for _ in range(max(1, a.repeat)):
                r = bench(n, a.steps, par, a.substeps, a.profile_kernels, extra)
                if best is None or r["element_substeps_per_s"] > best["element_substeps_per_s"]:
                    best = r
            r = best
            r["requested"] = {None: "auto", True: "parallel", False: "serial"}[par]
            r["triad_GB_s"] = triad["parallel" if r["parallel"] else "serial"]
            r["fraction_of_triad"] = r["achieved_GB_s"] / r["triad_GB_s"]  # of the triad at the start
            rows.append(r)
            mode = _mode(r)
            print(f"{r['n_elements']:>9} {mode:>12} {r['substeps_per_step']:>8.0f} "
                  f"{r['element_substeps_per_s'] / 1e6:>10.1f} {r['substep_loop_per_s'] / 1e6:>8.1f} "
                  f"{r['node_velocity_per_s'] / 1e6:>8.1f} "
                  f"{r['element_stress_damage_per_s'] / 1e6:>8.1f} {r['total_bytes']:>8.0f} "
                  f"{r['achieved_GB_s']:>6.2f} {100 * r['fraction_of_triad']:>6.0f} "
                  f"{r['overhead_ms_per_outer_step']:>16.1f} "
                  f"{r['loop_overhead_ms_per_outer_step']:>12.1f}", flush=True)
    try:
        layer = numba.threading_layer()
    except ValueError:
        layer = "none used"
    for r in rows:
        r["threading_layer"] = layer
    # The triad again after the kernels: on shared hosts it moved by up to 2x between runs
    # (docs/benchmarks.md, tenth session), so each row is also given as a fraction of the
    # best triad of the run, the bandwidth the machine showed it can deliver (the stricter
    # denominator of the two).
    triad_end = {"serial": stream_triad(False), "parallel": stream_triad(True)}
    best_triad = {k: max(triad[k], triad_end[k]) for k in triad}
    print(f"STREAM triad after the kernels: serial {triad_end['serial']:.2f} GB/s, parallel "
          f"{triad_end['parallel']:.2f} GB/s; fraction of the run's best triad:")
    for r in rows:
        r["best_triad_GB_s"] = best_triad["parallel" if r["parallel"] else "serial"]
        r["fraction_of_best_triad"] = r["achieved_GB_s"] / r["best_triad_GB_s"]
        mode = _mode(r)
        print(f"{r['n_elements']:>9} {mode:>12} {r['achieved_GB_s']:>6.2f} GB/s of {r['best_triad_GB_s']:.2f}: "
              f"{100 * r['fraction_of_best_triad']:.0f} %")
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps({"triad_GB_s": triad, "triad_GB_s_after": triad_end, "best_triad_GB_s": best_triad,
                                  "element_kernel_per_cpu_s": ek, "rows": rows}, indent=1))
    print(f"threading layer: {layer}; wrote {a.json}")


if __name__ == "__main__":
    main()
