"""Explicit solver throughput (issue 3): element-sub-steps per second, by kernel.

Builds the ``wind_square`` scene at resolutions giving about 10k, 50k and 200k
elements, runs a few outer steps after a warm-up (numba compilation excluded)
with damage active (a strong wind is already blowing: the scene clock starts
at 12 h), and prints element-sub-steps per second overall and per kernel
(node_velocity: internal-force gather + semi-implicit momentum; element_stress_damage:
strain rate + Maxwell stress + damage/healing), plus the per-outer-step
overhead (forcing evaluation, lumped mass, adjacency weights).

    python benchmarks/bench_explicit.py                      # 10k, 50k, 200k
    NUMBA_NUM_THREADS=2 python benchmarks/bench_explicit.py --elements 50000
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numba
import numpy as np

from lagice.scenes import wind_square
from lagice.stability import explicit_substep_limit

AREA_PER_ELEMENT = 1.15 * 0.5  # gmsh: elements ≈ 2·(L/Δx)²·1.15


def resolution_for(n_elements, domain_m=wind_square.DOMAIN_M):
    return domain_m * math.sqrt(2 * 1.15 / n_elements)


def bench(n_target, steps, parallel, substeps):
    sc = wind_square.build(resolution_m=resolution_for(n_target), parallel=parallel, ramp_h=1.0)
    sc.state.time_s = 12 * 3600.0  # full wind
    s = sc.solver
    # outer step holding `substeps` sub-steps (default 100, e.g. 15 min at 9 s) at the automatic (stable) sub-step size
    lim = explicit_substep_limit(s.dx_min, s.rheology.E0)
    sc.dt_s = substeps * s.safety * lim * 0.999
    for _ in range(2):
        s.step(sc.state, sc.dt_s)
    s.kernel_timings = {k: 0.0 for k in s.kernel_timings}
    n_sub = 0
    t0 = time.perf_counter()
    for _ in range(steps):
        info = s.step(sc.state, sc.dt_s)
        n_sub += info.iterations
    wall = time.perf_counter() - t0
    m = sc.mesh.n_elements
    es = m * n_sub
    kt = s.kernel_timings
    return {"n_elements": m, "n_nodes": sc.mesh.n_nodes, "resolution_m": sc.dx_m,
            "parallel": s._parallel_for(sc.mesh), "threads": numba.get_num_threads(),
            "outer_steps": steps, "substeps_per_step": n_sub / steps,
            "element_substeps_per_s": es / wall,
            "node_velocity_per_s": es / kt["node_velocity"],
            "element_stress_damage_per_s": es / kt["element_stress_damage"],
            "overhead_ms_per_outer_step": 1e3 * (kt["forcing"] + kt["setup"]) / steps,
            "mean_damage": float(np.mean(sc.state.damage)),
            "wall_s": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[10_000, 50_000, 200_000])
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--substeps", type=int, default=100)
    ap.add_argument("--parallel", choices=["auto", "yes", "no", "both"], default="both")
    ap.add_argument("--json", type=Path, default=Path("benchmarks/out/explicit.json"))
    a = ap.parse_args(argv)
    modes = {"auto": [None], "yes": [True], "no": [False], "both": [False, True]}[a.parallel]
    print(f"numba threads: {numba.get_num_threads()}  (threading layer set on first parallel call)")
    print(f"{'elements':>9} {'parallel':>8} {'sub/step':>8} {'Mel-sub/s':>10} {'node':>8} {'element':>8} "
          f"{'overhead ms/step':>16}")
    rows = []
    for n in a.elements:
        for par in modes:
            r = bench(n, a.steps, par, a.substeps)
            rows.append(r)
            print(f"{r['n_elements']:>9} {str(r['parallel']):>8} {r['substeps_per_step']:>8.0f} "
                  f"{r['element_substeps_per_s'] / 1e6:>10.1f} {r['node_velocity_per_s'] / 1e6:>8.1f} "
                  f"{r['element_stress_damage_per_s'] / 1e6:>8.1f} {r['overhead_ms_per_outer_step']:>16.1f}",
                  flush=True)
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
