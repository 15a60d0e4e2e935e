"""CPU ExplicitSolver vs CudaExplicitSolver through Model and Simulation on tiny
damaging problems; writes one JSON report.

Run by ``tests/test_cuda_explicit.py`` in a subprocess with
``NUMBA_ENABLE_CUDASIM=1`` (numba reads it at import, so the simulator must
not leak into the rest of the test suite). Can be run by hand on a machine
with a GPU (no simulator) to measure the agreement of a real device (the
report goes to REPORT.json, or to stdout):

    python tests/cuda_sim_compare.py [REPORT.json]           # GPU, or
    NUMBA_ENABLE_CUDASIM=1 python tests/cuda_sim_compare.py [REPORT.json]

The problem (about 60 elements, 4 outer steps of 50 s, automatic sub-steps):
wind and ocean current from record fields (wind on a coarse uniform grid:
time blend on the grid; current on a fine non-uniform grid: two-record
interpolation and binary-search cells; one step lands on a record time:
single record), ocean drag with a turning angle, Coriolis, a top edge pushed
by a time-dependent prescribed velocity, coast at the bottom, low cohesion
(damage within the first sub-steps), fast healing, a damage cap at 0.3
(capping happens), non-uniform thickness and concentration, and the mesh
moved by the MeshMotion component with the transport velocity (geometry
re-uploaded, thickness and concentration changed on the host every step).
"""
from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from forcing.records import InMemoryRecords, RecordField, RegularGrid
from lagice.drifters import Drifters
from lagice.errors import ForcingError, SolverError
from lagice.forces import Coriolis, OceanDrag, WindStress
from lagice.lagrangian import MeshMotion
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.remesh import Remesher
from lagice.rheology import MaxwellEB
from lagice.simulation import Simulation
from lagice.solvers import ExplicitSolver, VelocityBC
from lagice.solvers.cuda_explicit import CudaExplicitSolver
from lagice.state import IceState

L = 100e3
DT = 50.0
STEPS = 4
TINY = {"threads_per_block": 32, "max_blocks": 2}  # several blocks, grid-stride loops, fast simulation
FIELDS = ("velocity", "stress", "damage", "thickness", "concentration")


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


def host_wind(t, x, y):
    """A callable wind (evaluated on the host, then uploaded)."""
    return 12.0 + 0.01 * t + 2.0 * np.sin(x / 3e4), 4.0 * np.cos(y / 2e4)


def top_edge_u(t, x, y):
    return 0.2 * min(1.0, t / 100.0) * (0.5 + x / L)


#: neXtSIM's compressive term for the "pmax" variant [Pa]: P_max = P* h^1.5 exp(−20(1−A)) lies
#: within the spread of the problem's compressive mean stresses, so elements are above and below it
PMAX_PA = 2000.0


#: the optional rheology terms of the CPU kernel, one variant each (the explicit CPU stepper's
#: combinations): the relaxation that keeps the mean stress, alone and with the compressive
#: term; the return towards θ m I (θ = 1.5: a dilatant return); the dilatant viscous flow; the
#: effective failure stress, alone and with the return towards θ m I; closed cracks (with the mean
#: kept), alone and with the compressive term
OPTIONAL_VARIANTS = {"keep_mean": {"relax_mean_stress": False}, "keep_mean_pmax": {"relax_mean_stress": False},
                     "mean_stress": {"stress_correction": "mean_stress", "stress_correction_mean_fraction": 1.5},
                     "dilatancy": {"dilatancy_angle_deg": 20.0},
                     "effective": {"failure_stress": "effective"},
                     "effective_mean_stress": {"failure_stress": "effective", "stress_correction": "mean_stress",
                                               "stress_correction_mean_fraction": 1.5},
                     "closure": {"relax_mean_stress": False, "crack_closure": True},
                     "closure_pmax": {"relax_mean_stress": False, "crack_closure": True}}
#: the run each optional variant is compared with to show that it changed something (default: the
#: problem without optional terms; the variants with the compressive term against the same problem
#: with it, closed cracks against the mean kept without them)
VARIANT_BASE = {"keep_mean_pmax": "pmax", "closure": "keep_mean", "closure_pmax": "keep_mean_pmax",
                "effective_mean_stress": "mean_stress"}


def problem(variant="records"):
    poly, segs = rectangle_domain(L, L)
    mesh = generate_mesh(poly, 20e3, segments={"top": segs["top"], "coast": segs["bottom"]}, exterior_tag="free")
    times = np.arange(0.0, 1000.0, 100.0)
    # wind: 6 x 6 uniform grid (36 points < nodes: blended in time on the grid)
    wind = record_field(np.linspace(-30e3, L + 30e3, 6), np.linspace(-30e3, L + 30e3, 6), times, 15.0, 1,
                        "wind records")
    # current: 25 x 22 non-uniform grid (more points than nodes: two-record interpolation)
    xo = np.sort(np.r_[-30e3, L + 30e3, np.random.default_rng(2).uniform(-29e3, L + 29e3, 23)])
    current = record_field(xo, np.linspace(-30e3, L + 30e3, 22), times, 0.05, 3, "current records")
    if variant == "host":  # a callable wind (host path) and a constant current (filled on the device)
        wind, current = host_wind, (0.03, -0.02)
    forces = [WindStress(wind), OceanDrag(current, turning_angle_deg=25.0), Coriolis(latitude_deg=75.0)]
    bcs = [VelocityBC("top", u=top_edge_u, v=-0.02)]
    rheo = MaxwellEB(cohesion_min_pa=1e3, cohesion_max_pa=3e3, healing_time_s=2e3, max_damage=0.3,
                     max_pressure_pa=PMAX_PA if variant in ("pmax", "keep_mean_pmax", "closure_pmax") else None,
                     **OPTIONAL_VARIANTS.get(variant, {}))
    c = mesh.centroids()
    st = IceState.uniform(mesh, thickness_m=1.0 + 0.3 * np.sin(c[:, 0] / 2e4),
                          concentration=0.92 + 0.08 * np.cos(c[:, 1] / 3e4),
                          cohesion_pa=np.random.default_rng(4).uniform(1e3, 3e3, mesh.n_elements))
    return mesh, st, rheo, forces, bcs


def heal_callable(state, t_s):
    """A healing rate that reads the host damage (a device stepper must download it first)."""
    return 5e-4 * (1.0 + state.damage)


def heal_compliance(state, t_s):
    """Compliance-form healing (negative rate: 1/(1 − d) decreases at |H|; the sign
    convention of rheology.damage_step)."""
    return -2e-2 * (1.0 + state.damage)


def stepper(kind, mesh, rheo, forces, bcs, heal=False, **opts):
    kw = {"bcs": bcs, "forces": forces,
          "heal_rate": heal if callable(heal) else (heal_callable if heal else None)}
    if kind == "cpu":
        return ExplicitSolver(rheo, mesh, parallel=False, **kw)
    if kind == "cpu_parallel":
        return ExplicitSolver(rheo, mesh, parallel=True, **kw)
    return CudaExplicitSolver(rheo, mesh, **kw, **{**TINY, **opts})


def model(kind, variant="records", heal=False, remesh=False, **opts):
    mesh, st, rheo, forces, bcs = problem(variant)
    # the initial mesh has angles from 43.4°: a 46° threshold remeshes patches from the first step
    rm = Remesher(20e3, min_angle_deg=46.0) if remesh else None
    return Model(st, rheology=rheo, solver=stepper(kind, mesh, rheo, forces, bcs, heal, **opts), mover=MeshMotion(),
                 remesher=rm)


class Totals:
    """Callback: capped / damaged counts and sub-steps of every step."""

    def __init__(self):
        self.n_capped = self.n_damaged = 0
        self.substeps = []

    def __call__(self, sim):
        info = sim.model.last_report["solver"]
        self.n_capped += info.n_capped
        self.n_damaged += info.n_damaged
        self.substeps.append(info.iterations)


def run(m, steps=STEPS, max_speed_m_s=10.0):
    sim = Simulation(m, dt=DT, stop=steps * DT, progress=False, max_speed_m_s=max_speed_m_s)
    tot = Totals()
    sim.add_callback(tot, every="1 steps")
    sim.run()
    return result(m, tot)


def result(m, tot=None):
    st = m.state
    out = {f: getattr(st, f).copy() for f in FIELDS}
    eps = m.strain_rate  # None right after a remesh
    out.update(transport=m.transport_velocity.copy(), strain=np.zeros((0, 3)) if eps is None else eps.copy(),
               nodes=m.mesh.nodes.copy(),
               n_elements=m.mesh.n_elements, remeshes=st.counters.get("remesh_events", 0))
    if tot is not None:
        out.update(n_capped=tot.n_capped, n_damaged=tot.n_damaged, substeps=tot.substeps)
    return out


def rel_diff(a, b):
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return float("inf")
    if a.size == 0:
        return 0.0
    scale = float(np.abs(a).max())
    return float(np.abs(a - b).max()) / scale if scale > 0 else float(np.abs(a - b).max())


def compare(ref, res):
    out = {k: rel_diff(ref[k], res[k]) for k in (*FIELDS, "transport", "strain", "nodes")}
    for k in ("n_capped", "n_damaged", "substeps", "n_elements", "remeshes"):
        if k in ref and k in res:
            out[k] = [ref[k], res[k]]
    return out


def resume_across(first, second, tmp):
    """Run 2 steps on ``first`` with a checkpoint, then resume the checkpoint with a model on
    ``second`` for the remaining steps (Simulation.resume(path, model=...))."""
    m = model(first)
    sim = Simulation(m, dt=DT, stop=STEPS * DT, progress=False)
    sim.checkpoint("2 steps", Path(tmp) / f"{first}_{second}", keep=1)
    sim.run(n_steps=2)
    ck = sorted((Path(tmp) / f"{first}_{second}").glob("checkpoint_*.npz"))[-1]
    sim2 = Simulation.resume(ck, model=model(second))
    sim2.activities.pop("progress", None)
    sim2.run()
    return result(sim2.model)


def forcing_error(kind):
    """Nodes outside the forcing grid: the CPU's ForcingError text, state untouched."""
    mesh, st, rheo, forces, bcs = problem()
    s = stepper(kind, mesh, rheo, forces, bcs)
    mesh.nodes = mesh.nodes + np.array([45e3, 0.0])
    s.update_geometry()
    v0 = st.velocity.copy()
    try:
        s.step(st, 0.0, DT)
        msg = None
    except ForcingError as exc:
        msg = str(exc)
    assert np.array_equal(st.velocity, v0)
    return msg


def nan_checker_message(kind, how):
    """The NaN checker's SolverError: a NaN velocity at a free node ("nan"), or an ice
    speed above a tiny bound ("speed")."""
    m = model(kind, sync="explicit") if kind == "cuda" else model(kind)
    if how == "nan":
        free = int(np.setdiff1d(np.arange(m.mesh.n_nodes), m.mesh.boundary_edges)[0])  # an interior node
        m.state.velocity[free] = np.nan
    try:
        run(m, max_speed_m_s=1e-3 if how == "speed" else 10.0)
        return None
    except SolverError as exc:
        return str(exc)


def downloads_per_step():
    """sync="explicit" through Simulation with the activities that run every step of
    every run (the NaN checker, the signal stop), a wall-time limit and a callback declared
    stateless: the device clears velocity, stress and damage itself, and the stop checks
    and the callback read no state, so nothing is downloaded between steps. Also returns
    the copies and launches of each step (``HostPath.counts``)."""
    from lagice.activities import WallTimeLimit

    m = model("cuda", sync="explicit")
    sim = Simulation(m, dt=DT, stop=STEPS * DT, progress=False)
    sim.add(WallTimeLimit("1h"))
    # a callback that declares it reads no state (as the benchmarks' recorders do)
    sim.add_callback(lambda s: s.model.mesh.n_elements, every="1 steps", name="counter", needs_host_state=False)
    every_step = [sim.activities[k] for k in ("nan_checker", "signal_stop", "wall_time_limit", "counter")]
    stale, counts = [], []
    for a in every_step:
        a.run(sim)
    for _ in range(2):
        before = dict(m.stepper._io.counts)
        sim.model.step(DT)
        for a in every_step:
            a.run(sim)
        stale.append(list(m.stepper.host_stale))
        counts.append({k: v - before[k] for k, v in m.stepper._io.counts.items()})
    return stale, counts


# -- the scene path: TOML, builder, Simulation, checkpoints moving between devices --------------
#: wind_square at 100 km (66 elements), 4 steps of 10 min, weak ice (damage within the first step),
#: full wind from the start, a checkpoint and a snapshot every 2 steps
SCENE_OV = {"domain.resolution_m": 100e3, "run.duration": "40min", "solver.dt": 600.0, "run.progress": False,
            "output.plot": False, "output.every": "2 steps", "checkpoint.every": "2 steps",
            "initial.cohesion_pa": 2e3, "forcing.wind.params.ramp_h": 0.01}


def scene_arrays(run_dir, step):
    from lagice.io.checkpoint import read_checkpoint

    arrays, _ = read_checkpoint(Path(run_dir) / "checkpoints" / f"checkpoint_{step:010d}.npz")
    return arrays


def scene_runs(tmp):
    """Full runs on each device; then each run's step-2 checkpoint resumed on the other
    device (``Simulation.resume(path, overrides={"solver.device": ...})``)."""
    from lagice.scenes.builder import build_simulation
    from lagice.scenes.config import load_scene

    out = {}
    sims = {}
    for dev in ("cpu", "cuda"):
        sim = build_simulation(load_scene("wind_square", {**SCENE_OV, "solver.device": dev}), Path(tmp) / dev)
        sim.run()
        sims[dev] = sim
    out["fingerprints"] = [sims["cpu"].model.fingerprint(), sims["cuda"].model.fingerprint()]
    out["stepper_types"] = [type(sims[d].model.stepper).__name__ for d in ("cpu", "cuda")]
    out["mean_damage"] = float(np.mean(sims["cpu"].model.state.damage))
    ref = scene_arrays(Path(tmp) / "cpu", 4)
    out["keys"] = sorted(ref)
    out["cuda_vs_cpu"] = {k: rel_diff(ref[k], v) for k, v in scene_arrays(Path(tmp) / "cuda", 4).items()
                          if v.dtype.kind == "f"}
    for a, b in (("cpu", "cuda"), ("cuda", "cpu")):
        ck = Path(tmp) / a / "checkpoints" / f"checkpoint_{2:010d}.npz"
        sim = Simulation.resume(ck, overrides={"solver.device": b}, out_dir=Path(tmp) / f"{a}_to_{b}")
        out[f"{a}_to_{b}_stepper"] = type(sim.model.stepper).__name__
        sim.run()
        res = scene_arrays(Path(tmp) / f"{a}_to_{b}", 4)
        out[f"resume_{a}_to_{b}"] = {k: rel_diff(ref[k], v) for k, v in res.items() if v.dtype.kind == "f"}
    # host code that edits the damage between steps (undamaged new ice, thermo.new_ice_undamaged) on a
    # stepper that keeps the damage on the device (sync="explicit"): it must download it first
    ni = {}
    for dev in ("cpu", "cuda"):
        sim = build_simulation(load_scene("wind_square", {**SCENE_OV, **NEW_ICE_OV, "solver.device": dev}),
                               Path(tmp) / f"newice_{dev}")
        sim.run()
        ni[dev] = sim.model.state
        out[f"newice_diluted_m2_{dev}"] = sim.model.component("thermodynamics").damage_diluted_m2
    out["newice_cuda_vs_cpu"] = {k: rel_diff(getattr(ni["cpu"], k), getattr(ni["cuda"], k))
                                 for k in ("velocity", "stress", "damage", "thickness", "concentration")}
    return out


#: the scene with thermodynamics (air at -20 to -30 degC in January), 20 % open water, undamaged new ice
NEW_ICE_OV = {"thermo.enabled": True, "thermo.new_ice_undamaged": True, "forcing.air_temperature.kind": "synthetic",
              "run.start_date": "2026-01-15 00:00:00", "initial.concentration": 0.8}


# -- rigid motion: the transport velocity moves nodes and drifters (tests/test_engine.py) ----
CENTER = np.array([0.5 * L, 0.5 * L])
OMEGA = 2e-6  # s-1
U0 = np.array([0.08, -0.05])  # m s-1
RIGID_DT = 200.0  # s: 20 sub-steps of 10 s, within the stability limit at 25 km


def rigid(kind, xy):
    if kind == "translation":
        return np.broadcast_to(U0, xy.shape).copy()
    d = xy - CENTER
    return OMEGA * np.column_stack([-d[:, 1], d[:, 0]])


def rigid_motion(device, motion):
    poly, _ = rectangle_domain(L, L)
    mesh = generate_mesh(poly, 25e3, exterior_tag="free")
    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    st.velocity = rigid(motion, mesh.nodes)
    rheo = MaxwellEB(healing_time_s=None, cohesion_min_pa=1e9, cohesion_max_pa=1e9)
    s = (ExplicitSolver(rheo, mesh, substeps=20) if device == "cpu"
         else CudaExplicitSolver(rheo, mesh, substeps=20, sync="explicit", **TINY))
    dr = Drifters([[30e3, 40e3], [60e3, 70e3], [50e3, 20e3]])
    m = Model(st, rheology=rheo, solver=s, mover=MeshMotion(), drifters=dr)
    x0, d0 = m.mesh.nodes.copy(), dr.positions.copy()
    vs = []
    sim = Simulation(m, dt=RIGID_DT, stop=3 * RIGID_DT, progress=False)
    sim.add_callback(lambda s_: vs.append(s_.model.transport_velocity.copy()), every="1 steps")
    sim.run()
    ref = rigid(motion, x0)
    x = x0.copy()
    for v in vs:
        x = x + RIGID_DT * v
    out = {"first_vs_rigid": float(np.abs(vs[0] - ref).max() / np.abs(ref).max()),
           "nodes_vs_sum": float(np.abs(m.mesh.nodes - x).max()),
           "transport": np.array(vs), "nodes": m.mesh.nodes.copy()}
    if motion == "translation":
        out["nodes_vs_exact"] = float(np.abs(m.mesh.nodes - (x0 + 3 * RIGID_DT * U0)).max())
        out["drifters_vs_exact"] = float(np.abs(dr.positions - (d0 + 3 * RIGID_DT * U0)).max())
    return out


def main():
    t0 = time.perf_counter()
    rep = {"simulator": __import__("numba").config.ENABLE_CUDASIM == 1}
    ref = run(model("cpu"))
    rep.update(n_elements=ref["n_elements"], damage_max=float(ref["damage"].max()),
               damaged_fraction=float(np.mean(ref["damage"] > 0)))
    rep["cpu_parallel"] = compare(ref, run(model("cpu_parallel")))
    coop = model("cuda")  # sync="step", launch="auto"
    res_coop = run(coop)
    rep["cuda_step_sync"] = compare(ref, res_coop)
    # a register cap changes register allocation, not arithmetic: the same result, bit for bit
    # (on a device; the simulator has no registers and runs the uncapped kernel)
    rep["register_cap_64_vs_uncapped"] = compare(res_coop, run(model("cuda", max_registers=64)))
    try:
        model("cuda", max_registers=8)
        rep["register_cap_refused"] = None
    except Exception as exc:  # noqa: BLE001 - the message is the result
        rep["register_cap_refused"] = f"{type(exc).__name__}: {exc}"
    rep["paths"] = coop.stepper.forcing_paths
    rep["launch_auto"] = coop.stepper.launch_used
    rep["device_bytes_per_element"] = coop.stepper.device_bytes() / coop.mesh.n_elements
    rep["cuda_explicit_sync_launches"] = compare(ref, run(model("cuda", sync="explicit", launch="launches")))
    rep["heal_callable_explicit_sync"] = compare(run(model("cpu", heal=True)),
                                                 run(model("cuda", heal=True, sync="explicit")))
    cpu_compliance = run(model("cpu", heal=heal_compliance))
    rep["heal_compliance_explicit_sync"] = compare(cpu_compliance,
                                                   run(model("cuda", heal=heal_compliance, sync="explicit")))
    rep["heal_compliance_damage_mean"] = [float(ref["damage"].mean()), float(cpu_compliance["damage"].mean())]
    rep["remesh_explicit_sync"] = compare(run(model("cpu", remesh=True)),
                                          run(model("cuda", remesh=True, sync="explicit")))
    cpu_pmax = model("cpu", variant="pmax")
    res_pmax = run(cpu_pmax)
    rep["pmax_explicit_sync"] = compare(res_pmax, run(model("cuda", variant="pmax", sync="explicit")))
    rep["pmax_vs_without"] = rel_diff(ref["stress"], res_pmax["stress"])
    st = cpu_pmax.state
    sn = -0.5 * (st.stress[:, 0] + st.stress[:, 1])
    pm = cpu_pmax.rheology.max_pressure(st.thickness, st.concentration)
    rep["pmax_elements_below_above"] = [int(np.sum((sn > 0) & (sn < pm))), int(np.sum(sn > pm))]
    cpu_runs = {"records": ref, "pmax": res_pmax}
    for variant in OPTIONAL_VARIANTS:
        res_v = cpu_runs[variant] = run(model("cpu", variant=variant))
        rep[f"{variant}_explicit_sync"] = compare(res_v, run(model("cuda", variant=variant, sync="explicit")))
        rep[f"{variant}_launches"] = compare(res_v, run(model("cuda", variant=variant, launch="launches")))
        rep[f"{variant}_vs_without"] = rel_diff(cpu_runs[VARIANT_BASE.get(variant, "records")]["stress"],
                                                res_v["stress"])
    host = model("cuda", variant="host", sync="explicit")
    rep["host_fields"] = compare(run(model("cpu", variant="host")), run(host))
    rep["host_paths"] = host.stepper.forcing_paths
    with tempfile.TemporaryDirectory() as tmp:
        rep["resume_cpu_to_cuda"] = compare(ref, resume_across("cpu", "cuda", tmp))
        rep["resume_cuda_to_cpu"] = compare(ref, resume_across("cuda", "cpu", tmp))
        rep["scene"] = scene_runs(tmp)
    rep["outside_grid_messages"] = [forcing_error("cpu"), forcing_error("cuda")]
    rep["nan_messages"] = [nan_checker_message("cpu", "nan"), nan_checker_message("cuda", "nan")]
    rep["speed_messages"] = [nan_checker_message("cpu", "speed"), nan_checker_message("cuda", "speed")]
    rep["stale_after_nan_check"], rep["transfers_per_step"] = downloads_per_step()
    # direct driver copies and prepared launches (cuda_host.py) against numba's own calls: bit for bit
    # on a GPU (in the simulator both are numba's calls); with mesh motion, healing and remeshing
    fast = model("cuda", heal=True, remesh=True, sync="explicit")
    res_fast = run(fast)
    slow = model("cuda", heal=True, remesh=True, sync="explicit", fast_host=False)
    rep["host_path_fast_vs_numba"] = compare(res_fast, run(slow))
    rep["host_path"] = {"fast": fast.stepper._io.fast, "note": fast.stepper._io.note,
                        "counts": fast.stepper._io.counts, "numba_counts": slow.stepper._io.counts}
    for motion in ("translation", "rotation"):
        a, b = rigid_motion("cpu", motion), rigid_motion("cuda", motion)
        rep[f"rigid_{motion}"] = {**{k: v for k, v in b.items() if k not in ("transport", "nodes")},
                                  "transport_vs_cpu": rel_diff(a["transport"], b["transport"]),
                                  "nodes_vs_cpu": rel_diff(a["nodes"], b["nodes"])}
    rep["wall_s"] = time.perf_counter() - t0
    text = json.dumps(rep, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o))
    if len(sys.argv) > 1:
        Path(sys.argv[1]).write_text(text)
    else:
        print(text)


if __name__ == "__main__":
    main()
