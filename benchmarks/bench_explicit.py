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

    python benchmarks/bench_explicit.py                      # 10k, 50k, 200k
    NUMBA_NUM_THREADS=2 python benchmarks/bench_explicit.py --elements 50000
    python benchmarks/bench_explicit.py --quick              # 10k, serial, 2 timed steps
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numba
import numpy as np
from scene_runs import reset_timings, scene_dx_min, scene_simulation, timed_run

from lagice.params import MaxwellEBParams
from lagice.stability import explicit_substep_limit

DOMAIN_M = 500e3  # the wind_square basin
SAFETY = 0.7
WARMUP_STEPS = 2


def resolution_for(n_elements, domain_m=DOMAIN_M):
    """gmsh: elements ≈ 2.3 (L/Δx)²."""
    return domain_m * math.sqrt(2 * 1.15 / n_elements)


def bench(n_target, steps, parallel, substeps):
    res = resolution_for(n_target)
    ov = {"domain.resolution_m": res, "lagrangian.enabled": False, "forcing.wind.params.ramp_h": 0.0,
          "solver.substeps": substeps, "output.timeseries": None}
    if parallel is not None:
        ov["solver.parallel"] = parallel
    # the outer step: `substeps` sub-steps at SAFETY × the stability limit of undamaged ice
    lim = explicit_substep_limit(scene_dx_min("wind_square", ov), MaxwellEBParams().E0)
    dt = round(substeps * SAFETY * lim * 0.999, 6)
    n = WARMUP_STEPS + steps
    sim = scene_simulation("wind_square", {**ov, "solver.dt": dt, "run.duration": n * dt})
    model = sim.model
    st = model.stepper
    sim.run(n_steps=WARMUP_STEPS)  # numba compilation, damage starts
    reset_timings(model)
    sub0 = model.last_report["solver"].iterations
    wall = timed_run(sim)
    m = model.mesh.n_elements
    es = m * substeps * steps
    kt = st.kernel_timings
    return {"n_elements": m, "n_nodes": model.mesh.n_nodes, "resolution_m": res,
            "parallel": st.nodes.parallel_for(model.mesh), "threads": numba.get_num_threads(),
            "outer_steps": steps, "substeps_per_step": float(sub0),
            "element_substeps_per_s": es / wall,
            "node_velocity_per_s": es / kt["node_velocity"],
            "element_stress_damage_per_s": es / kt["element_stress_damage"],
            "overhead_ms_per_outer_step": 1e3 * (kt["forcing"] + kt["setup"]) / steps,
            "loop_overhead_ms_per_outer_step": 1e3 * (wall - model.timings["dynamics"]) / steps,
            "mean_damage": float(np.mean(model.state.damage)),
            "wall_s": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[10_000, 50_000, 200_000])
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--substeps", type=int, default=100)
    ap.add_argument("--parallel", choices=["auto", "yes", "no", "both"], default="both")
    ap.add_argument("--quick", action="store_true", help="10k elements, serial kernels, 2 timed steps")
    ap.add_argument("--json", type=Path, default=Path("benchmarks/out/explicit.json"))
    a = ap.parse_args(argv)
    if a.quick:
        a.elements, a.parallel, a.steps = [10_000], "no", 2
    modes = {"auto": [None], "yes": [True], "no": [False], "both": [False, True]}[a.parallel]
    print(f"numba threads: {numba.get_num_threads()}  (threading layer set on first parallel call)")
    print(f"{'elements':>9} {'parallel':>8} {'sub/step':>8} {'Mel-sub/s':>10} {'node':>8} {'element':>8} "
          f"{'overhead ms/step':>16} {'loop ms/step':>12}")
    rows = []
    for n in a.elements:
        for par in modes:
            r = bench(n, a.steps, par, a.substeps)
            rows.append(r)
            print(f"{r['n_elements']:>9} {str(r['parallel']):>8} {r['substeps_per_step']:>8.0f} "
                  f"{r['element_substeps_per_s'] / 1e6:>10.1f} {r['node_velocity_per_s'] / 1e6:>8.1f} "
                  f"{r['element_stress_damage_per_s'] / 1e6:>8.1f} {r['overhead_ms_per_outer_step']:>16.1f} "
                  f"{r['loop_overhead_ms_per_outer_step']:>12.1f}", flush=True)
    try:
        layer = numba.threading_layer()
    except ValueError:
        layer = "none used"
    for r in rows:
        r["threading_layer"] = layer
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(rows, indent=1))
    print(f"threading layer: {layer}; wrote {a.json}")


if __name__ == "__main__":
    main()
