"""What Crouzeix–Raviart velocities cost (``solver.velocity_element``, ``solver.jump_penalty``;
docs/solvers.md, "Crouzeix–Raviart velocities").

Runs ``winter_basin_pack`` from its shipped spun-up state through the scene builder and
``Simulation`` with linear velocities, Crouzeix–Raviart velocities, and Crouzeix–Raviart
velocities with the jump penalty, and prints the wall time of the time loop, the sub-steps per
outer step and the element-sub-steps per second of each (two warm-up steps first, so that
compilation is not timed).

    NUMBA_NUM_THREADS=1 python benchmarks/bench_velocity_element.py --resolution-km 20 --steps 48
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene

VARIANTS = (("linear", {}),
            ("crouzeix_raviart", {"solver.velocity_element": "crouzeix_raviart"}),
            ("crouzeix_raviart, jump_penalty 1", {"solver.velocity_element": "crouzeix_raviart",
                                                  "solver.jump_penalty": 1.0}))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution-km", type=float, default=20.0)
    ap.add_argument("--steps", type=int, default=48, help="outer steps timed (after 2 warm-up steps)")
    ap.add_argument("--parallel", choices=("false", "true", "auto"), default="false")
    args = ap.parse_args(argv)
    par = {"false": False, "true": True, "auto": "auto"}[args.parallel]
    print(f"winter_basin_pack at {args.resolution_km:g} km, {args.steps} outer steps, "
          f"solver.parallel = {args.parallel}")
    print("| velocity element | wall (s) | sub-steps per step | elements | M element-sub-steps/s | × linear |")
    print("|---|---|---|---|---|---|")
    base = None
    for name, ov in VARIANTS:
        cfg = load_scene("winter_basin_pack", {**ov, "domain.resolution_m": args.resolution_km * 1e3,
                                               "run.progress": False, "output.plot": False,
                                               "run.duration": "100d", "output.every": "100d",
                                               "checkpoint.every": "100d", "solver.parallel": par})
        with tempfile.TemporaryDirectory() as tmp:
            sim = build_simulation(cfg, Path(tmp) / "run")
            sim.run(n_steps=2)
            t = time.perf_counter()
            sim.run(n_steps=args.steps)
            wall = time.perf_counter() - t
            n_sub = sim.model.stepper.last_substeps
            m = sim.model.mesh.n_elements
        base = wall if base is None else base
        rate = args.steps * n_sub * m / wall / 1e6
        print(f"| {name} | {wall:.1f} | {n_sub} | {m} | {rate:.1f} | {wall / base:.1f} |", flush=True)


if __name__ == "__main__":
    main()
