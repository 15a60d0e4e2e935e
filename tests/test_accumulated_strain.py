"""output.accumulate_strain: the time integral of the strain rate the rheology used, carried by
the state through remeshing and checkpoints, and the window statistics taken from it
(lagice.diagnostics.windows.accumulated_strain_rates, benchmarks/window_split.py)."""
import numpy as np
import pytest
import xarray as xr

from lagice.diagnostics.windows import accumulated_strain_rates
from lagice.errors import ConfigError
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene
from lagice.simulation import Simulation

# as tests/test_simulation.py: a sheared box that cracks (FAST), and one whose mesh moves and remeshes
FAST = {"run.duration": 1600.0, "solver.dt": 40.0, "output.every": 800.0, "checkpoint.every": 800.0,
        "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
        "boundary.top.u": "5e-2*minimum(1.0, t/600.0)", "lagrangian.enabled": True}
REMESHING = {"run.duration": 6000.0, "solver.dt": 100.0, "output.every": 3000.0, "checkpoint.every": 3000.0,
             "domain.resolution_m": 25e3, "run.progress": False, "output.plot": False,
             "boundary.top.u": "20.0*minimum(1.0, t/600.0)", "lagrangian.enabled": True, "remesh.enabled": True,
             "run.max_speed_m_s": 50.0}


def _state(model):
    st = model.state
    return {"nodes": st.mesh.nodes, "velocity": st.velocity, "stress": st.stress, "damage": st.damage,
            "thickness": st.thickness, "cohesion": st.cohesion}


def test_accumulated_strain_changes_nothing_and_is_the_node_motion_with_linear_velocities(tmp_path):
    """The option is a diagnostic: the run ends in the same state bit for bit. With linear
    velocities the nodes move with the field the rheology uses, so over a window the rheology's
    mean strain rate (the accumulated strain's difference) is the node motion's Lagrangian rate, up
    to the change of the geometry over the window (1.5e-5 relative here, strains of about 3e-3)."""
    runs = {}
    for acc in (False, True):
        sim = build_simulation(load_scene("shear_box", {**FAST, "output.accumulate_strain": acc}),
                               tmp_path / f"acc{int(acc)}")
        sim.run()
        runs[acc] = sim
    a, b = _state(runs[False].model), _state(runs[True].model)
    for k in a:
        assert np.array_equal(a[k], b[k]), f"{k} differs with output.accumulate_strain"
    assert runs[False].model.state.strain_accumulated is None
    acc = runs[True].model.state.strain_accumulated
    assert acc.shape == (runs[True].model.mesh.n_elements, 3) and np.abs(acc).max() > 0
    assert runs[True].model.state.damage.max() > 0, "the box must crack for the test to mean something"
    last = xr.load_dataset(tmp_path / "acc1" / "snapshots" / "snapshot_00000040.nc")
    assert np.array_equal(last["strain_accumulated_xy"].values[0], acc[:, 2])
    assert last.attrs["strain_accumulated_since_s"] == 0.0
    assert "strain_accumulated_xy" not in xr.load_dataset(tmp_path / "acc0" / "snapshots" / "snapshot_00000040.nc")

    nodes, rheo, info = accumulated_strain_rates(tmp_path / "acc1", 0.0, 1600.0)
    assert info["dt_s"] == 1600.0 and nodes.gradient_s.shape == rheo.gradient_s.shape
    for name in ("divergence_s", "shear_s"):
        x, y = getattr(nodes, name), getattr(rheo, name)
        assert np.abs(x).max() > 1e-8, "the box must deform"
        rel = np.linalg.norm(y - x) / np.linalg.norm(x)
        assert rel < 1e-3, f"{name}: the rheology's window rate differs from the nodes' by {rel:.3g}"
    # the snapshots of the run without the option cannot be split, and say why
    with pytest.raises(ConfigError, match="output.accumulate_strain = true"):
        accumulated_strain_rates(tmp_path / "acc0", 0.0, 1600.0)


def test_accumulated_strain_through_remeshing_and_a_resume(tmp_path):
    """Remeshing remaps the field with the others (it keeps the mesh's element count), and a run
    resumed from a checkpoint ends with the uninterrupted run's field bit for bit."""
    cfg = {**REMESHING, "output.accumulate_strain": True}
    full = build_simulation(load_scene("shear_box", cfg), tmp_path / "full")
    full.run()
    st = full.model.state
    assert st.counters.get("remesh_events", 0) > 0, "the run must remesh for the test to mean something"
    assert st.strain_accumulated.shape == (st.mesh.n_elements, 3)
    part = build_simulation(load_scene("shear_box", cfg), tmp_path / "part")
    part.run(n_steps=30)  # checkpoint at step 30
    del part
    resumed = Simulation.resume(tmp_path / "part" / "checkpoints")
    resumed.run()
    assert np.array_equal(resumed.model.state.strain_accumulated, st.strain_accumulated)
    assert resumed.model.state.counters["strain_accumulated_since_s"] == 0.0
    # a window across the remeshes: every followed triangle gets the rheology's rate
    nodes, rheo, info = accumulated_strain_rates(tmp_path / "full", 0.0, 6000.0)
    assert info["remesh_events"] > 0 and np.all(np.isfinite(rheo.gradient_s))


def test_accumulated_strain_switched_on_by_a_resume_counts_from_it(tmp_path):
    """A run resumed with ``output.accumulate_strain`` from a checkpoint without the field counts
    from the resume: the counter and the snapshots say so, and a window that begins before it is
    refused by name, while one after it is split."""
    from lagice.scenes.builder import resume_simulation

    part = build_simulation(load_scene("shear_box", FAST), tmp_path / "run")
    part.run(n_steps=20)  # checkpoint at step 20 (t = 800 s), no accumulated strain
    assert part.model.state.strain_accumulated is None
    del part
    resumed = resume_simulation(tmp_path / "run" / "checkpoints", overrides={"output.accumulate_strain": True})
    resumed.run()
    st = resumed.model.state
    assert st.counters["strain_accumulated_since_s"] == 800.0 and st.strain_accumulated is not None
    with pytest.raises(ConfigError, match="no accumulated strain"):
        accumulated_strain_rates(tmp_path / "run", 0.0, 1600.0)
    nodes, rheo, _ = accumulated_strain_rates(tmp_path / "run", 800.0, 1600.0)
    assert np.linalg.norm(rheo.shear_s - nodes.shear_s) < 1e-3 * np.linalg.norm(nodes.shear_s)
