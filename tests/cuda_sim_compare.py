"""CPU ExplicitSolver vs CudaExplicitSolver on the same tiny damaging problem.

Run by ``tests/test_cuda_explicit.py`` in a subprocess with
``NUMBA_ENABLE_CUDASIM=1`` (numba reads it at import, so the simulator must
not leak into the rest of the test suite); prints one JSON object on stdout.
Can be run by hand on a machine with a GPU (no simulator) to measure the
agreement of the real device:

    python tests/cuda_sim_compare.py            # GPU, or
    NUMBA_ENABLE_CUDASIM=1 python tests/cuda_sim_compare.py

The problem (about 170 elements, 5 outer steps of 50 s, automatic sub-steps):
wind and ocean current from record fields (wind on a coarse uniform grid:
time blend on the grid; current on a fine non-uniform grid: two-record
interpolation and binary-search cells; one step lands on a record time:
single record), ocean drag with a turning angle, Coriolis, a top edge
pushed by a time-dependent prescribed velocity, coast at the bottom, low
cohesion (damage within the first sub-steps), fast healing, a damage cap at
0.3 (capping happens), non-uniform thickness and concentration, and the
nodes moved with the mean velocity after every step (geometry re-uploaded).
"""
from __future__ import annotations

import json
import sys
import time

import numpy as np

from forcing.records import InMemoryRecords, RecordField, RegularGrid
from lagice.errors import ForcingError, SolverError
from lagice.forces import Coriolis, OceanDrag, WindStress
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.rheology import MaxwellEB
from lagice.solvers import ExplicitSolver, VelocityBC
from lagice.solvers.cuda_explicit import CudaExplicitSolver
from lagice.state import IceState

L = 100e3
DT = 50.0
STEPS = 5


def record_field(x, y, times, scale, seed, name, **kw):
    rng = np.random.default_rng(seed)
    X, Y = np.meshgrid(x, y)
    data = np.empty((len(times), 2, len(y), len(x)))
    for k, t in enumerate(times):
        a, b, c = rng.uniform(0.5, 1.5, 3)
        data[k, 0] = scale * (a + 0.3 * np.sin(X / 3e4 + c) + 0.1 * t / 100.0)
        data[k, 1] = scale * (0.5 * b + 0.3 * np.cos(Y / 2.5e4 - c))
    grid = RegularGrid(x, y)
    return RecordField(InMemoryRecords(times, grid, data, ("u", "v"), units="m s-1", name=name), **kw)


def problem(variant="records"):
    poly, segs = rectangle_domain(L, L)
    mesh = generate_mesh(poly, 12e3, segments={"top": segs["top"], "coast": segs["bottom"]},
                         exterior_tag="free")
    times = np.arange(0.0, 1000.0, 100.0)
    # wind: 6 x 6 uniform grid (36 points < nodes: blended in time on the grid)
    wind = record_field(np.linspace(-30e3, L + 30e3, 6), np.linspace(-30e3, L + 30e3, 6), times, 15.0, 1,
                        "wind records")
    # current: 25 x 22 non-uniform grid (more points than nodes: two-record interpolation)
    xo = np.sort(np.r_[-30e3, L + 30e3, np.random.default_rng(2).uniform(-29e3, L + 29e3, 23)])
    current = record_field(xo, np.linspace(-30e3, L + 30e3, 22), times, 0.05, 3, "current records")
    if variant == "host":  # a callable wind (host path) and a constant current (filled on the device)
        wind = lambda t, x, y: (12.0 + 0.01 * t + 2.0 * np.sin(x / 3e4), 4.0 * np.cos(y / 2e4))
        current = (0.03, -0.02)
    forces = [WindStress(wind), OceanDrag(current, turning_angle_deg=25.0), Coriolis(latitude_deg=75.0)]
    bcs = [VelocityBC("top", u=lambda t, x, y: 0.2 * min(1.0, t / 100.0) * (0.5 + x / L), v=-0.02)]
    rheo = MaxwellEB(cohesion_min_pa=1e3, cohesion_max_pa=3e3, healing_time_s=2e3, max_damage=0.3)
    rng = np.random.default_rng(4)
    c = mesh.centroids()
    st = IceState.uniform(mesh, thickness_m=1.0 + 0.3 * np.sin(c[:, 0] / 2e4),
                          concentration=0.92 + 0.08 * np.cos(c[:, 1] / 3e4),
                          cohesion_pa=rng.uniform(1e3, 3e3, mesh.n_elements))
    return mesh, st, rheo, forces, bcs


def run(kind, steps=STEPS, switch_after=None, remesh_after=None, **opts):
    """Run ``steps`` outer steps; ``kind`` "cpu" or "cuda"; with ``switch_after``
    the first steps run on the CPU and the rest on the device (a checkpoint
    moving between devices); with ``remesh_after`` the state gets a new (copied)
    mesh after that many steps and the solver ``reset_topology``, as a remesh
    does (in ``sync="explicit"`` after ``to_host``, as docs/gpu.md asks)."""
    mesh, st, rheo, forces, bcs = problem(opts.pop("variant", "records"))
    heal = opts.pop("heal_callable", False)
    heal_rate = (lambda s: 5e-4 * (1.0 + s.damage)) if heal else None  # reads the host damage
    cpu = ExplicitSolver(rheo, mesh, bcs=bcs, forces=forces, heal_rate=heal_rate)
    dev = None
    n_capped = n_damaged = 0
    substeps = []
    for k in range(steps):
        on_dev = kind == "cuda" and (switch_after is None or k >= switch_after)
        if on_dev and dev is None:
            dev = CudaExplicitSolver(rheo, mesh, bcs=bcs, forces=forces, heal_rate=heal_rate, **opts)
        s = dev if on_dev else cpu
        info = s.step(st, DT)
        n_capped += info.n_capped
        n_damaged += info.n_damaged
        substeps.append(info.iterations)
        mv = s.mean_velocity
        mesh.nodes = mesh.nodes + DT * mv  # Lagrangian motion with the transport velocity
        s.update_geometry()
        if remesh_after is not None and k + 1 == remesh_after:
            if getattr(s, "sync", "step") == "explicit":
                s.to_host(st)
            mesh = mesh.copy()
            st.mesh = mesh
            s.reset_topology(mesh)
    s = dev if dev is not None else cpu
    if getattr(s, "sync", "step") == "explicit":
        assert set(s.host_stale) == {"velocity", "stress", "damage"}
        s.to_host(st)
    return {"velocity": st.velocity, "stress": st.stress, "damage": st.damage, "mean": s.mean_velocity,
            "strain": s.last_strain_rate, "nodes": mesh.nodes, "n_capped": n_capped, "n_damaged": n_damaged,
            "substeps": substeps, "solver": s}


def rel_diff(a, b):
    scale = float(np.abs(a).max())
    return float(np.abs(a - b).max()) / scale if scale > 0 else float(np.abs(a - b).max())


def compare(ref, res):
    out = {k: rel_diff(ref[k], res[k]) for k in ("velocity", "stress", "damage", "mean", "strain", "nodes")}
    out["n_capped"] = [ref["n_capped"], res["n_capped"]]
    out["n_damaged"] = [ref["n_damaged"], res["n_damaged"]]
    out["substeps"] = [ref["substeps"], res["substeps"]]
    return out


def main():
    t0 = time.perf_counter()
    tiny = {"threads_per_block": 32, "max_blocks": 2}
    ref = run("cpu")
    ref_heal = run("cpu", heal_callable=True)
    report = {"simulator": __import__("numba").config.ENABLE_CUDASIM == 1,
              "n_elements": len(ref["damage"]), "damage_max": float(ref["damage"].max()),
              "damaged_fraction": float(np.mean(ref["damage"] > 0))}
    coop = run("cuda", remesh_after=3, **tiny)
    report["paths"] = coop["solver"].forcing_paths
    report["launch_auto"] = coop["solver"].launch_used
    report["cooperative_step_sync"] = compare(ref, coop)
    report["launches_explicit_sync"] = compare(ref, run("cuda", sync="explicit", launch="launches",
                                                                 remesh_after=2, **tiny))
    report["heal_callable_explicit_sync"] = compare(ref_heal, run("cuda", sync="explicit", heal_callable=True,
                                                                  **tiny))
    report["cpu_then_cuda"] = compare(ref, run("cuda", switch_after=2, **tiny))
    host = run("cuda", variant="host", **tiny)
    report["host_paths"] = host["solver"].forcing_paths
    report["host_fields"] = compare(run("cpu", variant="host"), host)
    # the same ForcingError as the CPU when the mesh leaves the record grid
    msgs = []
    for kind in ("cpu", "cuda"):
        mesh, st, rheo, forces, bcs = problem()
        s = (ExplicitSolver(rheo, mesh, bcs=bcs, forces=forces) if kind == "cpu"
             else CudaExplicitSolver(rheo, mesh, bcs=bcs, forces=forces, **tiny))
        mesh.nodes = mesh.nodes + np.array([45e3, 0.0])
        s.update_geometry()
        v0 = st.velocity.copy()
        try:
            s.step(st, DT)
            msgs.append(None)
        except ForcingError as exc:
            msgs.append(str(exc))
        assert np.array_equal(st.velocity, v0) and st.step == 0
    report["outside_grid_messages"] = msgs
    # a NaN velocity: SolverError on both, state untouched
    msgs = []
    for kind in ("cpu", "cuda"):
        mesh, st, rheo, forces, bcs = problem()
        s = (ExplicitSolver(rheo, mesh, bcs=bcs, forces=forces) if kind == "cpu"
             else CudaExplicitSolver(rheo, mesh, bcs=bcs, forces=forces, **tiny))
        free = int(np.flatnonzero(s.fixed.sum(axis=1) == 0)[0])
        st.velocity[free] = np.nan
        d0 = st.damage.copy()
        try:
            s.step(st, DT)
            msgs.append(None)
        except SolverError as exc:
            msgs.append(str(exc).split(" (")[0])
        assert np.array_equal(st.damage, d0) and st.step == 0
    report["nan_messages"] = msgs
    report["device_bytes_per_element"] = coop["solver"].device_bytes() / len(ref["damage"])
    report["wall_s"] = time.perf_counter() - t0
    json.dump(report, sys.stdout, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o))


if __name__ == "__main__":
    main()
