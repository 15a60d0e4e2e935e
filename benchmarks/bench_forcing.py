"""Cost of forcing evaluation per model step (issue 5).

Wind (cyclones, 25 km grid, 6-hourly records) and ocean current (steady
gyre) at the nodes, air temperature (synthetic, 6-hourly) at the element
centroids (≈ 2 × nodes), at a time between records, for 20k and 200k nodes:

* ``cached``   — weights cached (``mesh_version`` unchanged): the per-step
  cost when positions did not change (gather + time interpolation only);
* ``compare``  — no ``mesh_version``, positions unchanged: + one O(n)
  comparison with the positions of the last build;
* ``moving``   — nodes moved every step (``mesh_version`` incremented):
  weights rebuilt every step (the Lagrangian default);
* ``rebuild``  — weight rebuild alone, per field;
* ``lonlat``   — ERA5-like lon/lat file (``data_stubs/era5_stub_arctic.nc``,
  wind + t2m): cached evaluation and rebuild (pyproj inverse projection).

Then the share of forcing in a real run: the ``winter_basin`` scene (scene builder +
Simulation, the path of ``lagice run``) for a few outer steps after a warm-up, with
the explicit stepper's ``kernel_timings`` (``forcing``: wind, ocean and Coriolis
terms at the nodes) against the dynamics time of the model, and the thermodynamics
component's time (air temperature at the centroids included) from ``model.timings``.

    python benchmarks/bench_forcing.py            # 20k and 200k nodes; winter_basin at 10 km
    python benchmarks/bench_forcing.py --quick    # 20k nodes; winter_basin at 20 km

(numba compile excluded by a warm-up call). The goal of issue 5 is < 5 % of the
explicit solver's step.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numba  # noqa: E402

import forcing._numba_util as numba_util  # noqa: E402
from forcing import Forcing, RegularGrid, cyclone_wind, gyre_current, open_air_temperature, open_wind, random_cyclones  # noqa: E402
from thermo import synthetic_air_temperature  # noqa: E402

DAY = 86400.0
BOX = (-5.0e5, 5.0e5, -5.0e5, 5.0e5)


def timeit(fn, repeat=15):
    fn()
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(ts))


def bench(n_nodes, forcing, rng):
    x = rng.uniform(BOX[0] + 1e4, BOX[1] - 1e4, n_nodes)
    y = rng.uniform(BOX[2] + 1e4, BOX[3] - 1e4, n_nodes)
    xc = rng.uniform(BOX[0] + 1e4, BOX[1] - 1e4, 2 * n_nodes)
    yc = rng.uniform(BOX[2] + 1e4, BOX[3] - 1e4, 2 * n_nodes)
    forcing.prepare(0.0, 3 * DAY, x, y, xc, yc)
    t = 1.3 * DAY
    res = {}
    res["cached"] = timeit(lambda: forcing.evaluate(t, x, y, xc, yc, mesh_version=0))
    res["compare"] = timeit(lambda: forcing.evaluate(t, x, y, xc, yc))
    state = {"v": 0}

    def moving():
        x[:] += 1.0
        xc[:] += 1.0
        state["v"] += 1
        forcing.evaluate(t, x, y, xc, yc, mesh_version=state["v"])

    res["moving"] = timeit(moving)
    w = forcing.wind
    res["rebuild"] = timeit(lambda: w._build_weights(x, y))
    return res


def bench_lonlat(n_nodes, rng):
    path = ROOT / "data_stubs" / "era5_stub_arctic.nc"
    wind, temp = open_wind(path), open_air_temperature(path)
    x = rng.uniform(-1.5e6, 1.5e6, n_nodes)
    y = rng.uniform(-1.5e6, 1.5e6, n_nodes)
    f = Forcing(wind=wind, air_temperature=temp)
    f.prepare(0.0, 3 * DAY, x, y)
    t = 1.3 * DAY
    cached = timeit(lambda: f.evaluate(t, x, y, mesh_version=0))
    rebuild = timeit(lambda: wind._build_weights(x, y), repeat=5)
    return cached, rebuild


def winter_basin_share(resolution_m, steps, warmup=2):
    """Forcing and thermodynamics time against the dynamics of ``winter_basin`` (ms per step)."""
    from scene_runs import reset_timings, scene_simulation, timed_run

    sim = scene_simulation("winter_basin", {"domain.resolution_m": resolution_m, "drifters.count": 0})
    model = sim.model
    sim.run(n_steps=warmup)
    reset_timings(model)
    wall = timed_run(sim, n_steps=steps)
    kt, tm = model.stepper.kernel_timings, model.timings
    return {"resolution_m": resolution_m, "n_nodes": model.mesh.n_nodes, "n_elements": model.mesh.n_elements,
            "steps": steps, "substeps": model.last_report["solver"].iterations,
            "ms_step": 1e3 * wall / steps, "ms_dynamics": 1e3 * tm["dynamics"] / steps,
            "ms_forcing": 1e3 * kt["forcing"] / steps, "ms_thermodynamics": 1e3 * tm["thermodynamics"] / steps}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="20k nodes only; winter_basin at 20 km")
    a = ap.parse_args(argv)
    sizes = (20_000,) if a.quick else (20_000, 200_000)
    grid = RegularGrid.from_bbox(*BOX, spacing_m=25e3)
    cyc = random_cyclones(BOX, 3 * DAY, 3, seed=1)
    rng = np.random.default_rng(0)
    print(f"numba threads: {numba.get_num_threads()}, threading layer: "
          f"{numba.config.THREADING_LAYER}; kernels switch to their parallel build from "
          f"{numba_util.PARALLEL_MIN_SIZE} points")
    default_min = numba_util.PARALLEL_MIN_SIZE
    for mode, min_size in (("default (serial < 50k points, parallel above)", default_min),
                           ("serial kernels only", 10**15)):
        numba_util.PARALLEL_MIN_SIZE = min_size
        forcing = Forcing(wind=cyclone_wind(grid, 3 * DAY, cyc, background_m_s=(2.0, 0.0)),
                          ocean=gyre_current(grid, 0.1),
                          air_temperature=synthetic_air_temperature(grid, 3 * DAY, seed=1))
        print(f"\n[{mode}]")
        print("synthetic records on a 25 km x/y grid: wind + ocean at n nodes, "
              "air temperature at 2n centroids [ms per step]")
        print(f"{'nodes':>8} {'cached':>9} {'compare':>9} {'moving':>9} {'rebuild(1 field)':>17}")
        for n in sizes:
            r = bench(n, forcing, rng)
            print(f"{n:>8} {r['cached']:>9.3f} {r['compare']:>9.3f} {r['moving']:>9.3f} "
                  f"{r['rebuild']:>17.3f}")
        print("ERA5-like lon/lat file (wind + t2m at n nodes) [ms per step]")
        print(f"{'nodes':>8} {'cached':>9} {'rebuild wind (pyproj)':>22}")
        for n in sizes:
            c, rb = bench_lonlat(n, rng)
            print(f"{n:>8} {c:>9.3f} {rb:>22.3f}")
    numba_util.PARALLEL_MIN_SIZE = default_min
    r = winter_basin_share(20e3 if a.quick else 10e3, 3 if a.quick else 10)
    print(f"\n[winter_basin at {r['resolution_m'] / 1e3:g} km through Simulation: {r['n_elements']} elements, "
          f"{r['n_nodes']} nodes, {r['substeps']} sub-steps per 10-min step]")
    print(f"outer step {r['ms_step']:.1f} ms: dynamics {r['ms_dynamics']:.1f} ms, of which forcing "
          f"{r['ms_forcing']:.2f} ms ({100 * r['ms_forcing'] / r['ms_dynamics']:.1f} % of the explicit step); "
          f"thermodynamics (air temperature included) {r['ms_thermodynamics']:.2f} ms")


if __name__ == "__main__":
    main()
