"""10-day shear scenes (through Simulation): many remesh events, no inverted
element, ice volume kept to 1e-10."""
import numpy as np
import pytest
import xarray as xr

from lagice.mesh import signed_areas
from lagice.remesh import totals
from lagice.scenes.builder import finish

from helpers import scene_sim


class MinArea:
    """Callback: smallest element area seen after every step, and bounds of A and d."""

    def __init__(self):
        self.min_area = np.inf

    def __call__(self, sim):
        st = sim.model.state
        self.min_area = min(self.min_area, signed_areas(st.mesh.nodes, st.mesh.triangles).min())
        assert st.concentration.max() <= 1.0 and st.damage.max() < 1.0


def test_ten_day_shear_channel_conserves_and_never_inverts(tmp_path):
    sim = scene_sim("shear_channel", tmp_path, {"solver.velocity_params.speed_m_s": 0.2, "output.every": "10d"})
    st = sim.model.state
    t0 = totals(st.mesh, st)
    ia0 = t0["ice_area_m2"]
    check = MinArea()
    sim.add_callback(check, every="1 steps")
    sim.run()
    st = sim.model.state
    t1 = totals(st.mesh, st)
    summ = sim.model.component("remeshing").log.summary()
    assert sim.model.clock.time_s == 10 * 86400.0
    assert summ["n_events"] >= 15 and summ["n_local"] >= 10 and summ["n_failed"] == 0
    assert check.min_area > 0
    assert abs(t1["ice_volume_m3"] - t0["ice_volume_m3"]) <= 1e-10 * t0["ice_volume_m3"]
    assert abs(t1["snow_volume_m3"] - t0["snow_volume_m3"]) <= 1e-10 * t0["snow_volume_m3"]
    # ice area: what ridging removed is booked
    budget = sim.model.component("mesh_motion").budget
    assert abs(t1["ice_area_m2"] + budget["ridged_ice_area_m2"] - ia0) <= 1e-10 * ia0
    # coast nodes never moved
    r = np.hypot(*st.mesh.nodes[st.mesh.coast_nodes()].T)
    assert np.all((np.abs(r - 100e3) < 1e-6) | (np.abs(r - 30e3) < 1e-6))
    assert sim.model.volume_budget()["relative_residual"] < 1e-10


def test_shear_channel_run_writes_outputs(tmp_path):
    sim = scene_sim("shear_channel", tmp_path, {"run.duration": "12h", "output.plot": True})
    res = finish(sim)
    ds = xr.load_dataset(tmp_path / "timeseries.nc")
    assert ds["ice_volume"].size == 13  # the start and 12 hourly steps
    assert np.all(np.diff(ds["time"].values) > 0)
    assert res["png"].exists()


@pytest.mark.slow
def test_ten_day_shear_channel_with_implicit_dynamics(tmp_path):
    """Same channel, ice driven by ocean drag through the ImplicitSolver:
    remeshes many times, never inverts, volume kept to 1e-10."""
    sim = scene_sim("shear_channel_implicit", tmp_path, {"output.every": "10d"})
    st = sim.model.state
    v0 = totals(st.mesh, st)["ice_volume_m3"]
    check = MinArea()
    sim.add_callback(check, every="1 steps")
    sim.run()
    st = sim.model.state
    summ = sim.model.component("remeshing").log.summary()
    assert sim.model.clock.time_s == 10 * 86400.0
    assert check.min_area > 0
    assert summ["n_events"] >= 10 and summ["n_failed"] == 0
    assert abs(totals(st.mesh, st)["ice_volume_m3"] - v0) <= 1e-10 * v0
    assert sim.model.stepper.mesh is st.mesh
    assert np.hypot(*st.velocity.T).max() > 0.1  # the ice does go round
