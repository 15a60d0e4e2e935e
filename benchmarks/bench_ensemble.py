"""Ensemble throughput: the same members one by one vs on a 2-worker dask LocalCluster.

The ensemble is ``examples/ensembles/winter_basin_seeds.toml``: 4 members of
the winter basin at 20 km for 2 days (explicit solver, thermodynamics,
remeshing), differing in their cohesion and cyclone seeds. Both runs go
through the command line as a user would (process start, imports, numba cache
loads included):

    serial:    lagice ensemble SPEC --out OUT/serial --serial      (members one by one, one process)
    ensemble:  lagice ensemble SPEC --out OUT/dask --workers W     (LocalCluster, W worker processes)

Both use NUMBA_NUM_THREADS = 1 per process: at this size (about 7k elements,
below ``LAGICE_PARALLEL_MIN_SIZE`` = 200k) lagice runs the serial builds of its
kernels anyway, so one member per core is the only way to use several cores.

Each mode runs ``--repeat`` times, alternating (serial, ensemble, ensemble,
serial, ...), and the best wall time of each is reported. The machine is
shared: before each run the script waits (up to ``--wait-idle`` s) for the
1-minute load average to fall below ``--idle-load``, and prints the load
average before and after every run; each member also records its CPU time,
so ``CPU / wall`` shows how much of the time it actually had a core.

Reported: wall time of each command and the speed-up; per-member wall and CPU
times; the busiest worker's summed member wall time (the critical path) and the
orchestration overhead (command wall − critical path: process start, cluster
start, scheduling, the summary), per member. The members' last snapshots of
the serial and every ensemble run are compared bit for bit.

    python benchmarks/bench_ensemble.py                       # 4 runs, ~4 min on an idle 2-core machine
    python benchmarks/bench_ensemble.py --repeat 1 --wait-idle 0

Writes ``docs/figures/ensemble.json``.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "ensembles" / "winter_basin_seeds.toml"


def loadavg() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def run_cli(args, env) -> tuple[float, str]:
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "lagice.cli", "ensemble", *args], env=env, capture_output=True,
                       text=True, check=False)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"bench_ensemble: lagice ensemble {' '.join(args)} failed ({r.returncode}):\n{r.stdout}\n{r.stderr}")
    return wall, r.stdout


def member_records(out: Path) -> dict:
    recs = {}
    for d in sorted((out / "members").iterdir()):
        recs[d.name] = json.loads((d / "done.json").read_text())
    return recs


def last_snapshot(member_dir: Path) -> Path:
    idx = json.loads((member_dir / "snapshots" / "index.json").read_text())
    return member_dir / "snapshots" / idx[-1]["file"]


def identical(a_dir: Path, b_dir: Path) -> bool:
    a = xr.load_dataset(last_snapshot(a_dir), decode_times=False)
    b = xr.load_dataset(last_snapshot(b_dir), decode_times=False)
    return set(a.variables) == set(b.variables) and all(np.array_equal(a[v].values, b[v].values) for v in a.variables)


def wait_idle(max_wait_s: float, idle_load: float) -> tuple[bool, float]:
    """Wait until the 1-minute load average is below ``idle_load`` (at most ``max_wait_s``)."""
    t0 = time.perf_counter()
    while os.getloadavg()[0] >= idle_load and time.perf_counter() - t0 < max_wait_s:
        time.sleep(5)
    return os.getloadavg()[0] < idle_load, time.perf_counter() - t0


def phase(name, args, env, out: Path, k: int, max_wait_s: float, idle_load: float) -> dict:
    idle, waited = wait_idle(max_wait_s, idle_load)
    la0 = loadavg()
    c0 = os.times()
    wall, screen = run_cli(args, env)
    c1 = os.times()
    la1 = loadavg()
    recs = member_records(out)
    busy = defaultdict(float)
    for r in recs.values():
        busy[r["worker"]] += r["wall_s"]
    res = {"run": k, "mode": name, "wall_s": wall, "loadavg_before": la0, "loadavg_after": la1,
           "idle_before": idle, "waited_s": waited,
           "cpu_children_s": (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system),
           "member_wall_s": {m: r["wall_s"] for m, r in recs.items()},
           "member_cpu_s": {m: r["cpu_s"] for m, r in recs.items()},
           "member_worker": {m: r["worker"] for m, r in recs.items()},
           "critical_path_s": max(busy.values()), "sum_member_wall_s": sum(r["wall_s"] for r in recs.values()),
           "sum_member_cpu_s": sum(r["cpu_s"] for r in recs.values())}
    res["outside_members_s"] = wall - res["critical_path_s"]
    ready = re.search(r"ready in ([0-9.]+) s", screen)
    res["cluster_start_s"] = float(ready.group(1)) if ready else 0.0
    res["cpu_share"] = res["sum_member_cpu_s"] / res["sum_member_wall_s"]
    print(f"  run {k} {name:<8} {wall:7.1f} s wall, members {res['sum_member_wall_s']:6.1f} s wall / "
          f"{res['sum_member_cpu_s']:6.1f} s CPU, load average before {la0} after {la1}"
          + ("" if idle else f" (machine not idle after waiting {waited:.0f} s)"), flush=True)
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(SPEC))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=2, help="runs of each mode, alternating (best is reported)")
    ap.add_argument("--wait-idle", type=float, default=300.0,
                    help="before each run, wait up to this many seconds for the 1-min load average to drop below "
                         "--idle-load")
    ap.add_argument("--idle-load", type=float, default=0.5)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "out" / "ensemble"))
    ap.add_argument("--json", default=str(ROOT / "docs" / "figures" / "ensemble.json"))
    args = ap.parse_args(argv)
    out = Path(args.out)
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    spec_name = str(Path(args.spec).resolve().relative_to(ROOT)) if Path(args.spec).resolve().is_relative_to(ROOT) \
        else args.spec

    # warm the numba cache once so no run pays compilation
    subprocess.run([sys.executable, "-m", "lagice.cli", "run", "shear_box", "--out", str(out / "warm"),
                    "--set", "domain.resolution_m=40e3", "--set", "run.duration=20min",
                    "--set", "output.plot=false"], env=env, capture_output=True, check=True)
    cores = len(os.sched_getaffinity(0))
    print(f"bench_ensemble: {spec_name}, {args.workers} workers, {cores} cores, load average now {loadavg()}",
          flush=True)
    runs = []
    for k in range(args.repeat):
        order = ("serial", "ensemble") if k % 2 == 0 else ("ensemble", "serial")
        for mode in order:
            d = out / f"{mode}_{k}"
            cli = [args.spec, "--out", str(d), "--no-plot"] + (["--serial"] if mode == "serial"
                                                               else ["--workers", str(args.workers)])
            runs.append(phase(mode, cli, env, d, k, args.wait_idle, args.idle_load))
    ser = min((r for r in runs if r["mode"] == "serial"), key=lambda r: r["wall_s"])
    ens = min((r for r in runs if r["mode"] == "ensemble"), key=lambda r: r["wall_s"])
    members = sorted(ser["member_wall_s"])
    n = len(members)
    same = all(identical(out / f"serial_{ser['run']}" / "members" / m, out / f"ensemble_{r['run']}" / "members" / m)
               for r in runs if r["mode"] == "ensemble" for m in members)
    res = {"spec": spec_name, "workers": args.workers, "cores": cores, "members": n, "host": platform.node(),
           "python": platform.python_version(), "numba_threads_per_process": 1,
           "serial_wall_s": ser["wall_s"], "ensemble_wall_s": ens["wall_s"], "speedup": ser["wall_s"] / ens["wall_s"],
           "ideal_speedup": min(args.workers, n, cores),
           "ensemble_overhead_s": ens["outside_members_s"], "cluster_start_s": ens["cluster_start_s"],
           "ensemble_overhead_per_member_s": ens["outside_members_s"] / n,
           "serial_outside_members_s": ser["wall_s"] - ser["sum_member_wall_s"],
           "member_wall_ratio_ensemble_serial": ens["sum_member_wall_s"] / ser["sum_member_wall_s"],
           "member_cpu_ratio_ensemble_serial": ens["sum_member_cpu_s"] / ser["sum_member_cpu_s"],
           "bit_identical": same, "best_serial_run": ser["run"], "best_ensemble_run": ens["run"], "runs": runs,
           "command_serial": f"NUMBA_NUM_THREADS=1 lagice ensemble {spec_name} --out OUT --serial --no-plot",
           "command_ensemble": (f"NUMBA_NUM_THREADS=1 lagice ensemble {spec_name} --out OUT "
                                f"--workers {args.workers} --no-plot"),
           "reproduce": f"python benchmarks/bench_ensemble.py --workers {args.workers} --repeat {args.repeat}"}
    print()
    print("| member | serial: wall (s) | serial: CPU (s) | ensemble: wall (s) | ensemble: CPU (s) |")
    print("|---|---:|---:|---:|---:|")
    for m in members:
        print(f"| {m} | {ser['member_wall_s'][m]:.1f} | {ser['member_cpu_s'][m]:.1f} | "
              f"{ens['member_wall_s'][m]:.1f} | {ens['member_cpu_s'][m]:.1f} |")
    print()
    print(f"| best of {args.repeat} | serial (`--serial`) | ensemble (`--workers {args.workers}`) |")
    print("|---|---:|---:|")
    print(f"| command wall time (s) | {ser['wall_s']:.1f} | {ens['wall_s']:.1f} |")
    print(f"| speed-up | 1 | {res['speedup']:.2f} (ideal {res['ideal_speedup']}) |")
    print(f"| members: wall / CPU, summed (s) | {ser['sum_member_wall_s']:.1f} / {ser['sum_member_cpu_s']:.1f} | "
          f"{ens['sum_member_wall_s']:.1f} / {ens['sum_member_cpu_s']:.1f} |")
    print(f"| busiest worker, summed member wall (s) | {ser['sum_member_wall_s']:.1f} | {ens['critical_path_s']:.1f} |")
    print(f"| outside the members (s) | {res['serial_outside_members_s']:.1f} | {ens['outside_members_s']:.1f} |")
    print(f"| of which cluster start (s) | - | {ens['cluster_start_s']:.1f} |")
    print(f"| overhead per member (s) | {res['serial_outside_members_s'] / n:.2f} | "
          f"{res['ensemble_overhead_per_member_s']:.2f} |")
    print(f"| load average before (1, 5, 15 min) | {ser['loadavg_before']} | {ens['loadavg_before']} |")
    print(f"| load average after | {ser['loadavg_after']} | {ens['loadavg_after']} |")
    print(f"\nmember results bit-identical between serial and every ensemble run: {same}")
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(res, indent=1))
    print(f"wrote {args.json}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
