"""Implicit solver benchmark (issue 2): compression scene at several N.

Runs ``uniaxial_compression`` (scene builder + Simulation) with N elements across
the plate (``domain.resolution_m = 100 km / N``) and each linear solver
(``solver.linear_solver``). Prints elements, unknowns, wall time per step split
into assembly / solve / damage update, fixed-point iterations per step and linear
iterations: the step reports (``StepInfo``) are recorded by a callback activity
after every step. The clock starts after a warm-up (numba compilation and first
factorisation are excluded) and covers steps through the elastic phase and, with
``--preload``, steps during active damage.

    python benchmarks/bench_implicit.py                  # N = 40, 100; all solvers
    python benchmarks/bench_implicit.py --n 70 --solvers cg --steps 50
    python benchmarks/bench_implicit.py --quick          # N = 20, cg, 10 steps
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from scene_runs import Recorder, scene_simulation, timed_run

PLATE_WIDTH_M = 100e3  # uniaxial_compression: 100 km x 200 km


def bench(n_across, linear_solver, steps, warmup=3, preload_strain=0.0):
    sim = scene_simulation("uniaxial_compression", {
        "domain.resolution_m": PLATE_WIDTH_M / n_across, "solver.linear_solver": linear_solver,
        "run.seed": 1, "output.timeseries": None})
    model = sim.model
    if preload_strain > 0:
        # start near failure: uniform uniaxial compressive stress close to the envelope so
        # that damage is active during the timed steps (an initial condition the scene's
        # isotropic initial.stress_pa cannot express)
        model.state.stress[:, 1] = -preload_strain * model.rheology.params.E0
    rec = Recorder(sim, solver_info=True)
    sim.run(n_steps=warmup)
    rec.clear()
    wall = timed_run(sim, n_steps=steps)
    tm = {"assembly": 0.0, "solve": 0.0, "damage": 0.0}
    its = lin = dam = 0
    for info in rec.infos:
        for k, v in info.timings.items():
            tm[k] += v
        its += info.iterations
        lin += info.linear_iterations
        dam += info.n_damaged
    mesh = model.mesh
    return {
        "n_across": n_across, "n_elements": mesh.n_elements, "n_unknowns": 2 * mesh.n_nodes,
        "linear_solver": linear_solver, "steps": steps,
        "ms_per_step": 1e3 * wall / steps,
        **{f"ms_{k}": 1e3 * v / steps for k, v in tm.items()},
        "fixed_point_iterations_per_step": its / steps,
        "linear_iterations_per_step": lin / steps,
        "damaged_elements_per_step": dam / steps,
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[40, 100])
    ap.add_argument("--solvers", nargs="+", default=["cg", "superlu", "amg"])
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--preload", type=float, default=2.4e-4,
                    help="initial uniform compressive strain so damage is active (0: elastic only)")
    ap.add_argument("--quick", action="store_true", help="N = 20, cg only, 10 steps")
    ap.add_argument("--json", type=Path, default=Path(__file__).resolve().parent / Path("out/implicit.json"))
    a = ap.parse_args(argv)
    if a.quick:
        a.n, a.solvers, a.steps = [20], ["cg"], 10
    rows = []
    hdr = (f"{'N':>4} {'elements':>9} {'unknowns':>9} {'solver':>8} {'ms/step':>8} {'assembly':>9} "
           f"{'solve':>7} {'damage':>7} {'fp it':>6} {'lin it':>7} {'damaged':>8}")
    print(hdr)
    for n in a.n:
        for s in a.solvers:
            r = bench(n, s, a.steps, preload_strain=a.preload)
            rows.append(r)
            print(f"{r['n_across']:>4} {r['n_elements']:>9} {r['n_unknowns']:>9} {s:>8} "
                  f"{r['ms_per_step']:>8.1f} {r['ms_assembly']:>9.1f} {r['ms_solve']:>7.1f} "
                  f"{r['ms_damage']:>7.1f} {r['fixed_point_iterations_per_step']:>6.1f} "
                  f"{r['linear_iterations_per_step']:>7.1f} {r['damaged_elements_per_step']:>8.0f}",
                  flush=True)
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(rows, indent=1))
    print(f"wrote {a.json}")


if __name__ == "__main__":
    main()
