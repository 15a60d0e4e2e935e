"""GPU explicit stepper (issue 15): refusal without a GPU, scene option, and
agreement with the CPU ExplicitSolver in numba's CUDA simulator.

numba reads ``NUMBA_ENABLE_CUDASIM`` when it is imported, so everything that
runs kernels runs in subprocesses with the variable set (``tests/cuda_sim_compare.py``
and the CLI); this process never enables the simulator. The refusal tests
run without it and are skipped where a GPU is usable.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lagice.errors import ConfigError
from lagice.scenes import toml_scene
from lagice.scenes.config import load_scene
from lagice.solvers import cuda_explicit
from lagice.solvers.cuda_explicit import check_solver_device, cuda_status

ROOT = Path(__file__).resolve().parents[1]
LAGICE = str(Path(sys.executable).parent / "lagice")
GPU_USABLE = cuda_status()[0]
no_gpu_only = pytest.mark.skipif(GPU_USABLE, reason="a CUDA device (or the simulator) is usable here")
TOL = 1e-12  # relative to the field's largest value; reached: see docs/gpu.md


def _env(simulator: bool) -> dict:
    env = dict(os.environ)
    env.pop("NUMBA_ENABLE_CUDASIM", None)
    if simulator:
        env["NUMBA_ENABLE_CUDASIM"] = "1"
    env.setdefault("NUMBA_NUM_THREADS", "1")
    return env


# ----------------------------------------------------------------------------
# no GPU: a clear ConfigError naming solver.device, before any mesh work
# ----------------------------------------------------------------------------
@no_gpu_only
def test_cli_cuda_without_gpu_fails_before_any_work(tmp_path):
    out = tmp_path / "run"
    r = subprocess.run([LAGICE, "run", "shear_box", "--set", 'solver.device="cuda"', "--set",
                        'solver.name="explicit"', "--out", str(out)],
                       check=False, capture_output=True, text=True, env=_env(False), timeout=120)
    assert r.returncode == 2, r.stderr
    assert 'lagice: error: solver.device = "cuda": no CUDA GPU is usable' in r.stderr
    assert "numba.cuda.is_available() is False" in r.stderr
    assert 'Use solver.device = "cpu" (the default)' in r.stderr
    assert "NUMBA_ENABLE_CUDASIM=1" in r.stderr
    assert not out.exists()  # nothing was built or written


@no_gpu_only
def test_build_refuses_cuda_before_meshing(tmp_path, monkeypatch):
    def no_mesh(*a, **k):
        raise AssertionError("mesh generation reached")

    monkeypatch.setattr(toml_scene, "generate_mesh", no_mesh)
    cfg = load_scene("shear_box", {"solver.device": "cuda", "solver.name": "explicit"})
    with pytest.raises(ConfigError, match=r'^solver\.device = "cuda": no CUDA GPU is usable'):
        toml_scene.build_simulation(cfg, tmp_path)
    # the solver itself refuses too, before touching the mesh it is given
    with pytest.raises(ConfigError, match=r"solver\.device"):
        cuda_explicit.CudaExplicitSolver(None, None)


def test_device_option_schema_and_checks(monkeypatch):
    assert load_scene("shear_box")["solver"]["device"] == "cpu"
    with pytest.raises(ConfigError, match=r"solver\.device = 'gpu': expected one of \['cpu', 'cuda'\]"):
        toml_scene.validate_components(load_scene("shear_box", {"solver.device": "gpu"}))
    with pytest.raises(ConfigError, match=r"solver\.device = 1: expected string"):
        load_scene("shear_box", {"solver.device": 1})
    check_solver_device({"device": "cpu", "name": "implicit"})  # default: nothing to check
    # with a device available, only the explicit solver runs on it
    monkeypatch.setattr(cuda_explicit, "require_cuda", lambda key="solver.device": "a GPU")
    with pytest.raises(ConfigError, match=r'solver\.device = "cuda" runs the explicit solver only; '
                                          r"solver\.name = 'implicit'"):
        check_solver_device({"device": "cuda", "name": "implicit"})
    check_solver_device({"device": "cuda", "name": "explicit"})


# ----------------------------------------------------------------------------
# compilation for a real device (NVVM, no GPU needed): what the simulator cannot see
# ----------------------------------------------------------------------------
@pytest.mark.slow
def test_every_kernel_compiles_for_sm90():
    """Every kernel compiles to PTX for an H100 (sm_90) with the signatures the
    solver launches; with ptxas it assembles, and the grid-sync kernel links
    with libcudadevrt (as the driver links it at load). Skipped without NVVM."""
    from numba.cuda.dispatcher import CUDADispatcher

    from lagice.solvers import cuda_kernels as K

    r = subprocess.run([sys.executable, str(ROOT / "tests" / "cuda_ptx_check.py")], check=False,
                       capture_output=True, text=True, env=_env(False), timeout=300, cwd=ROOT)
    assert r.returncode == 0, r.stderr[-3000:]
    rep = json.loads(r.stdout)
    if not rep["nvvm"]:
        pytest.skip(f"no NVVM to compile with: {rep['reason']}")
    kernels = {name for name, obj in vars(K).items()
               if isinstance(obj, CUDADispatcher) and not obj.targetoptions.get("device")}
    assert set(rep["kernels"]) == kernels  # the check covers every kernel
    for name, k in rep["kernels"].items():
        assert k["ok"], (name, k.get("error"))
        assert k.get("ptxas_ok", True), (name, k.get("ptxas_error"))
    coop = rep["kernels"]["substeps_cooperative"]
    assert coop["grid_sync"] and coop.get("linked_with_cudadevrt", True), coop.get("nvlink_error")


# ----------------------------------------------------------------------------
# simulator: the device kernels against the CPU kernels
# ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def sim_report():
    r = subprocess.run([sys.executable, str(ROOT / "tests" / "cuda_sim_compare.py")], check=False,
                       capture_output=True, text=True, env=_env(True), timeout=300, cwd=ROOT)
    assert r.returncode == 0, r.stderr[-3000:]
    return json.loads(r.stdout)


@pytest.mark.slow
def test_simulator_matches_cpu_on_damaging_run(sim_report):
    """Wind and current from records on the device, drag, Coriolis, a prescribed
    moving edge, damage, healing, the damage cap, moving nodes: velocity, stress,
    damage, mean velocity and its strain rate agree with the CPU solver to
    round-off after 5 outer steps, in both launch modes, both sync modes, with
    a heal-rate callable, after switching from CPU to device mid-run (a state
    moving between devices), and with host-evaluated / constant fields."""
    r = sim_report
    assert r["simulator"] is True
    assert r["paths"] == {"wind": "device", "ocean": "device"}
    assert r["host_paths"] == {"wind": "host", "ocean": "constant"}
    assert r["launch_auto"] == "cooperative"
    # the problem does what it claims: damage spreads and the cap acts
    assert r["damaged_fraction"] > 0.2 and r["damage_max"] == 0.3
    for case in ("cooperative_step_sync", "launches_explicit_sync", "heal_callable_explicit_sync",
                 "cpu_then_cuda", "host_fields"):
        c = r[case]
        for field in ("velocity", "stress", "damage", "mean", "strain", "nodes"):
            assert c[field] <= TOL, (case, field, c[field])
        cpu, dev = c["n_capped"]
        assert cpu == dev and cpu > 0, case
        cpu, dev = c["n_damaged"]
        assert cpu == dev and cpu > 0, case
        assert c["substeps"][0] == c["substeps"][1] and min(c["substeps"][0]) > 1, case


@pytest.mark.slow
def test_simulator_errors_match_cpu(sim_report):
    """A mesh leaving the forcing grid raises the CPU's ForcingError text; a NaN
    velocity raises SolverError; both leave the state untouched (checked in
    the script)."""
    a, b = sim_report["outside_grid_messages"]
    assert a is not None and a == b and "lie outside the forcing grid" in a
    a, b = sim_report["nan_messages"]
    assert a is not None and a == b and a.startswith("non-finite velocity")


def _snapshot(out):
    import xarray as xr

    idx = json.loads((out / "snapshots" / "index.json").read_text())
    last = max((out / "snapshots").glob("snapshot_*.nc"))
    with xr.open_dataset(last) as ds:
        return idx, {k: ds[k].values.copy() for k in ("velocity_x", "velocity_y", "damage", "stress",
                                                      "total_deformation_rate")}


@pytest.mark.slow
def test_cli_scene_on_simulator_matches_cpu(tmp_path):
    """The scene path end to end (TOML, CLI, Model, netCDF output) with
    ``solver.device = "cuda"`` in the simulator gives the CPU run's fields."""
    args = ["--set", 'solver.name="explicit"', "--set", "run.duration=120", "--set", "output.every=120",
            "--set", "output.plot=false", "--set", "rheology.cohesion_min_pa=1e3",
            "--set", "rheology.cohesion_max_pa=2e3", "--set", 'boundary.top.u="0.3*minimum(1.0, t/60.0)"']
    res = {}
    for dev in ("cpu", "cuda"):
        out = tmp_path / dev
        r = subprocess.run([LAGICE, "run", "shear_box", *args, "--set", f'solver.device="{dev}"',
                            "--out", str(out)], check=False, capture_output=True, text=True,
                           env=_env(dev == "cuda"), timeout=300)
        assert r.returncode == 0, r.stderr[-3000:]
        res[dev] = _snapshot(out)[1]
    cpu, dev = res["cpu"], res["cuda"]
    assert np.mean(cpu["damage"] > 0) > 0.1  # the run damages
    for k in cpu:
        scale = np.abs(cpu[k]).max()
        assert scale > 0 and np.abs(cpu[k] - dev[k]).max() <= TOL * scale, k
