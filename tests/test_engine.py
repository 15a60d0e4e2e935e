"""The one engine: every stepper moves the mesh, the drifters and the snapshot
displacements with one transport velocity; the explicit stepper's shipped
stability limit holds through Simulation; every bundled scene runs, checkpoints
and resumes bit for bit through the CLI."""
import json
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from lagice.drifters import Drifters
from lagice.errors import ConfigError, SolverError
from lagice.lagrangian import MeshMotion
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.model import Model
from lagice.rheology import MaxwellEB, ViscousPlastic
from lagice.simulation import Simulation
from lagice.solvers import PrescribedStepper
from lagice.stability import explicit_substep_limit

L = 100e3
CENTER = np.array([0.5 * L, 0.5 * L])
OMEGA = 2e-6  # s-1: a rigid rotation (100 km box: 0.1 m/s at the corners)
U0 = np.array([0.08, -0.05])  # m s-1


def rigid(kind, xy):
    if kind == "translation":
        return np.broadcast_to(U0, xy.shape).copy()
    d = xy - CENTER
    return OMEGA * np.column_stack([-d[:, 1], d[:, 0]])


def build(stepper, kind, mesh):
    from lagice.state import IceState

    st = IceState.uniform(mesh, thickness_m=1.0, concentration=1.0, cohesion_pa=1e9)
    st.velocity = rigid(kind, mesh.nodes)
    dr = Drifters([[30e3, 40e3], [60e3, 70e3], [50e3, 20e3]])
    if stepper == "prescribed":
        def field(t, x, y):
            v = rigid(kind, np.column_stack([x, y]))
            return v[:, 0], v[:, 1]
        return Model(st, solver=PrescribedStepper(mesh=mesh, velocity=field), mover=MeshMotion(), drifters=dr)
    rheo = (ViscousPlastic(replacement_pressure=True) if stepper == "evp"
            else MaxwellEB(healing_time_s=None, cohesion_min_pa=1e9, cohesion_max_pa=1e9))
    opts = {"substeps": 60} if stepper in ("explicit", "evp") else {}
    return Model(st, rheology=rheo, solver=stepper, solver_options=opts, mover=MeshMotion(), drifters=dr)


class Recorder:
    """Callback: node positions and transport velocity after every step."""

    def __init__(self):
        self.v = []

    def __call__(self, sim):
        self.v.append(sim.model.transport_velocity.copy())


@pytest.mark.parametrize("kind", ["translation", "rotation"])
@pytest.mark.parametrize("stepper", ["implicit", "explicit", "evp", "prescribed"])
def test_nodes_drifters_snapshots_move_with_the_transport_velocity(stepper, kind, tmp_path):
    poly, _ = rectangle_domain(L, L)
    mesh = generate_mesh(poly, 20e3, exterior_tag="free")  # nothing fixed: the ice may move rigidly
    model = build(stepper, kind, mesh)
    x0 = model.mesh.nodes.copy()
    d0 = model.drifters.positions.copy()
    dt, n = 600.0, 6
    sim = Simulation(model, dt=dt, stop=n * dt, progress=False)
    sim.output(every="1 steps", path=tmp_path, crs=None)
    rec = Recorder()
    sim.add_callback(rec, every="1 steps")
    sim.run()
    # the first step: the transport velocity is the rigid field itself (no strain, no stress)
    ref = rigid(kind, x0)
    assert np.abs(rec.v[0] - ref).max() <= 1e-12 * np.abs(ref).max()
    # every node moved by exactly dt × the transport velocity of each step
    x = x0.copy()
    for v in rec.v:
        x = x + dt * v
    assert np.abs(model.mesh.nodes - x).max() <= 1e-9  # metres, after 6 steps of ~500 m
    if kind == "translation":
        assert np.abs(model.mesh.nodes - (x0 + n * dt * U0)).max() < 1e-8
        assert np.abs(model.drifters.positions - (d0 + n * dt * U0)).max() < 1e-8
    # snapshots: consecutive node positions differ by dt × the velocity they report
    idx = json.loads((tmp_path / "index.json").read_text())
    assert len(idx) == n + 1
    for a, b in zip(idx[:-1], idx[1:]):
        sa = xr.load_dataset(tmp_path / a["file"], decode_times=False)
        sb = xr.load_dataset(tmp_path / b["file"], decode_times=False)
        dx = sb["mesh_node_x"].values - sa["mesh_node_x"].values
        dy = sb["mesh_node_y"].values - sa["mesh_node_y"].values
        assert np.abs(dx - dt * sb["velocity_x"].values[0]).max() < 1e-9
        assert np.abs(dy - dt * sb["velocity_y"].values[0]).max() < 1e-9


def _wind_square(tmp_path, ratio, allow_unstable=False, steps=60):
    """wind_square at 50 km with sub-steps at ``ratio`` × the shipped stability limit, on
    undamageable ice (as the limit was measured: damage would soften an unstable run)."""
    from helpers import scene_sim

    ov = {"domain.resolution_m": 50e3, "run.duration": "1d", "solver.substeps": 10,
          "forcing.wind.params.ramp_h": 1.0, "initial.cohesion_pa": 1e9}
    if allow_unstable:
        ov["solver.allow_unstable"] = True
    sim = scene_sim("wind_square", tmp_path, ov)
    st = sim.model.stepper
    lim = explicit_substep_limit(st.dx_min, st.rheology.E0, st.rheology.params)
    dt = 10 * ratio * lim
    return Simulation(sim.model, dt=dt, stop=steps * dt, progress=False)


def test_explicit_stability_limit_through_simulation(tmp_path):
    """0.9 × the shipped limit runs stably; 1.2 × is refused; beyond the limit with
    allow_unstable the run blows up and the NaN checker stops it naming field, step and
    place. (At 1.2 × the unstable sub-step oscillation saturates near 2 m/s under the
    quadratic ocean drag, and cancels out of the sub-step mean; at 2 × it runs away.)"""
    ok = _wind_square(tmp_path / "a", 0.9)
    ok.run()
    v = ok.model.state.velocity
    assert np.all(np.isfinite(v)) and np.abs(v).max() < 1.0  # m/s: stable, physical
    refused = _wind_square(tmp_path / "b", 1.2)
    with pytest.raises(ConfigError, match="exceeds the measured stability limit"):
        refused.run(n_steps=1)
    from lagice.stability import StabilityWarning

    blow = _wind_square(tmp_path / "c", 2.0, allow_unstable=True, steps=400)
    with pytest.warns(StabilityWarning), pytest.raises(SolverError, match=r"ice speed .* above the bound 10 m/s "
                                                                          r".* at step \d+ .* in node \d+ at x = "):
        blow.run()
    assert 0 < blow.model.clock.iteration < 400  # it ran unstably for a while, then was stopped


def _coarse(name, path):
    """Overrides that make a bundled scene tiny: a coarse mesh, 4 steps, a checkpoint
    and a snapshot every 2 steps."""
    from lagice.scenes.config import load_scene

    cfg = load_scene(path)
    res = cfg["domain"]["resolution_m"]
    coarse = max(4.0 * res, 12.5e3) if isinstance(res, (int, float)) else None
    ov = [f"run.duration={4 * _dt(cfg, coarse)}", 'checkpoint.every="2 steps"', 'output.every="2 steps"',
          "output.plot=false", "run.progress=false"]
    if coarse:
        ov.append(f"domain.resolution_m={coarse}")
    return ov


def _dt(cfg, coarse):
    from lagice.scenes.builder import time_step_s

    if cfg["solver"]["dt"] == "td" and coarse:
        cfg = {**cfg, "domain": {**cfg["domain"], "resolution_m": coarse}}
    return time_step_s(cfg)


def _cli(*args):
    r = subprocess.run([sys.executable, "-m", "lagice.cli", *args], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    return r


def _bundled():
    from lagice.scenes.config import list_scenes

    return sorted(list_scenes().items())


@pytest.mark.slow
@pytest.mark.parametrize("name,entry", _bundled(), ids=[n for n, _ in _bundled()])
def test_every_bundled_scene_runs_checkpoints_and_resumes_bit_identically(name, entry, tmp_path):
    path, _desc = entry
    sets = []
    for s in _coarse(name, path):
        sets += ["--set", s]
    _cli("run", name, "--out", str(tmp_path / "full"), *sets)
    _cli("run", name, "--out", str(tmp_path / "part"), *sets)
    ck = tmp_path / "part" / "checkpoints"
    files = sorted(ck.glob("checkpoint_*.npz"))
    assert [int(p.stem.split("_")[1]) for p in files] == [2, 4]
    files[-1].unlink()  # back to step 2, as after a crash
    (tmp_path / "part" / "snapshots" / "snapshot_00000004.nc").unlink()
    _cli("resume", str(ck))
    a = xr.load_dataset(tmp_path / "full" / "snapshots" / "snapshot_00000004.nc", decode_times=False)
    b = xr.load_dataset(tmp_path / "part" / "snapshots" / "snapshot_00000004.nc", decode_times=False)
    for var in a.data_vars:
        if var != "crs":
            assert np.array_equal(a[var].values, b[var].values), f"{name}: {var} differs after resume"
    from lagice.io.checkpoint import read_checkpoint

    fa, _ = read_checkpoint(tmp_path / "full" / "checkpoints" / "checkpoint_0000000004.npz")
    fb, _ = read_checkpoint(ck / "checkpoint_0000000004.npz")
    assert fa.keys() == fb.keys()
    for k in fa:
        assert np.array_equal(fa[k], fb[k]), f"{name}: checkpoint array {k} differs after resume"


def test_damage_time_step_reaches_the_healing_component(tmp_path):
    """solver.dt = "td" (Δt = Δx/cs) is one outer step for every component: the
    thermodynamic healing law gets the same Δt as the simulation (it used to read
    solver.dt as a duration and fail on "td")."""
    from lagice.scenes.builder import build_simulation
    from lagice.scenes.config import load_scene

    cfg = load_scene("winter_basin", {"domain.resolution_m": 60e3, "solver.dt": "td", "run.duration": "1h",
                                      "healing.law": "thermodynamic", "output.plot": False})
    sim = build_simulation(cfg, tmp_path / "run")
    expected = 60e3 / cfg["rheology"]["shear_wave_speed"]
    assert sim.dt == pytest.approx(expected, rel=1e-12)
    assert sim.model.healing.dt_s == pytest.approx(expected, rel=1e-12)
