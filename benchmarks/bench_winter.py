"""The flagship run's wall time by component (issue 15 item 4): ``winter_basin``.

Builds the ``winter_basin`` scene (scene builder + Simulation, the path of ``lagice
run``) at ``--resolution`` (default 10 km, the scene's own), with its outputs
(daily snapshots, checkpoints every 2 days) written to a temporary folder, runs one
warm-up step (numba kernels loaded from the cache, the serial/parallel choice
measured), zeroes the timings and times ``--days`` simulated days. Printed: wall
time and its split into

* dynamics: the explicit stepper's step, itself split into forcing (wind, ocean
  current and Coriolis terms at the nodes), setup (lumped mass, adjacency weights,
  moduli) and the sub-step loop (the two kernels), the rest (strain rate of the
  transport velocity, copies);
* thermodynamics (air temperature at the centroids included), mesh motion,
  remeshing, drifters (``model.timings``);
* output and the other activities (snapshots, checkpoints, NaN checker): wall − model;

element-sub-steps per second (over the sub-step loop and over the whole wall
time), and the 28-day wall time extrapolated linearly from the measured days (the
sub-step count is set by the undamaged modulus, so the cost per day is nearly
constant; remeshing grows as the mesh deforms, so the extrapolation is a lower
bound when remeshing is a large share).

    python benchmarks/bench_winter.py                        # 2 days, kernels as solver.parallel=auto
    NUMBA_NUM_THREADS=2 python benchmarks/bench_winter.py --parallel both --days 2
    python benchmarks/bench_winter.py --quick                # 20 km, 1 day
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numba
from scene_runs import Recorder, reset_timings, scene_simulation, timed_run

DAY_S = 86400.0
COMPONENTS = ("dynamics", "mesh_motion", "thermodynamics", "remeshing", "drifters")


def bench(days: float, resolution_m: float, parallel, outputs: bool = True, extra=None) -> dict:
    ov = {"domain.resolution_m": resolution_m, "run.duration": days * DAY_S + 600.0, **(extra or {})}
    if parallel is not None:
        ov["solver.parallel"] = parallel
    sim = scene_simulation("winter_basin", ov, outputs=outputs)
    model = sim.model
    st = model.stepper
    sim.run(n_steps=1)  # warm-up: kernels loaded, the kernel choice measured
    reset_timings(model)
    # reads the mesh and the step's report only: no state download on the GPU (until 2026-11-26,
    # sixth session, it downloaded velocity, stress and damage every step: +3 uploads, +2 downloads)
    rec = Recorder(sim, needs_host_state=False, el_sub=lambda m: m.mesh.n_elements * m.last_report["solver"].iterations)
    wall = timed_run(sim)
    tm = dict(model.timings)
    kt = st.kernel_timings
    es = float(rec["el_sub"].sum())
    gpu = not hasattr(st, "nodes")  # the CUDA stepper (solver.device = "cuda")
    choice = getattr(st, "kernel_choice", None) or {}
    if gpu:
        choice = {"parallel": False, "threads": 1, "method": f"cuda, launch {st.launch_used}"}
    par = choice["parallel"] if "parallel" in choice else st.nodes.parallel_for(model.mesh)
    sub_s = kt.get("substeps", 0.0) or (kt["node_velocity"] + kt["element_stress_damage"])
    split = {"dynamics": tm.get("dynamics", 0.0),
             "  forcing": kt["forcing"], "  setup": kt["setup"], "  sub-step loop": sub_s}
    if gpu:
        split["  host-device transfers"] = kt.get("transfer", 0.0)
    split["  rest of the step"] = tm.get("dynamics", 0.0) - sum(v for k, v in split.items() if k != "dynamics")
    for k in COMPONENTS[1:]:
        split[k] = tm.get(k, 0.0)
    split["output and activities"] = wall - sum(tm.get(k, 0.0) for k in COMPONENTS)
    steps = len(rec.time_s)
    simulated_days = steps * sim.dt / DAY_S
    return {"device": "cuda" if gpu else "cpu", "resolution_m": resolution_m,
            "n_elements": model.mesh.n_elements, "steps": steps,
            "simulated_days": simulated_days, "parallel": par,
            "threads": choice.get("threads", numba.get_num_threads() if par else 1),
            "choice": choice.get("method", "fixed rule"), "choice_timings_ms": choice.get("timings_ms", {}),
            "substeps_per_step": es / steps / model.mesh.n_elements, "wall_s": wall, "split_s": split,
            "element_substeps_per_s_loop": es / sub_s, "element_substeps_per_s_wall": es / wall,
            "remesh_count": int(model.state.counters.get("remesh_count", 0)),
            "wall_28d_extrapolated_s": wall * 28.0 / simulated_days,
            **({"host_path": {"direct_copies": st._io.fast, "prepared_launches": st._io.prepared_launches,
                              "note": st._io.note,
                              "per_step": {k: v / steps for k, v in st._io.counts.items()}}} if gpu else {})}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--days", type=float, default=2.0)
    ap.add_argument("--resolution", type=float, default=10e3, help="element size [m]")
    ap.add_argument("--parallel", choices=["auto", "yes", "no", "both"], default="auto")
    ap.add_argument("--no-outputs", action="store_true", help="leave snapshots and checkpoints out")
    ap.add_argument("--quick", action="store_true", help="20 km, 1 day")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="scene override as `lagice run --set` (e.g. domain.renumber=false)")
    ap.add_argument("--json", type=Path, default=Path(__file__).resolve().parent / Path("out/winter.json"))
    a = ap.parse_args(argv)
    from lagice.scenes.config import _split

    extra = dict(_split(kv) for kv in a.set)
    if a.quick:
        a.days, a.resolution = 1.0, 20e3
    modes = {"auto": [None], "yes": [True], "no": [False], "both": [False, True]}[a.parallel]
    rows = []
    for par in modes:
        r = bench(a.days, a.resolution, par, outputs=not a.no_outputs, extra=extra)
        r["overrides"] = a.set
        r["requested"] = {None: "auto", True: "parallel", False: "serial"}[par]
        rows.append(r)
        kern = "GPU" if r["device"] == "cuda" else f"parallel on {r['threads']} threads" if r["parallel"] else "serial"
        print(f"winter_basin {r['resolution_m'] / 1e3:g} km, {r['n_elements']} elements, "
              f"{r['simulated_days']:.2f} days ({r['steps']} steps, {r['substeps_per_step']:.0f} sub-steps each), "
              f"solver.parallel={r['requested']}: {kern} ({r['choice']})")
        for k, v in r["split_s"].items():
            print(f"  {k:<24} {v:8.2f} s  {100 * v / r['wall_s']:5.1f} %")
        print(f"  {'wall':<24} {r['wall_s']:8.2f} s   ({r['remesh_count']} remeshes)")
        print(f"  element-sub-steps/s: {r['element_substeps_per_s_loop'] / 1e6:.1f} M in the sub-step loop, "
              f"{r['element_substeps_per_s_wall'] / 1e6:.1f} M over the wall time; "
              f"28 days extrapolated: {r['wall_28d_extrapolated_s']:.0f} s", flush=True)
        if "host_path" in r:  # the GPU stepper's calls to the device per step (docs/gpu.md: each costs host time)
            c = r["host_path"]["per_step"]
            print(f"  GPU calls per step: {c['uploads']:.1f} uploads, {c['downloads']:.1f} downloads, "
                  f"{c['launches']:.1f} launches", flush=True)
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(rows, indent=1))
    print(f"wrote {a.json}")


if __name__ == "__main__":
    main()
