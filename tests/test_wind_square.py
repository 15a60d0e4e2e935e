"""Scene wind_square (through the scene builder and Simulation): rotation
invariance, outputs, the turning-wind hook, bad input."""
import math

import numpy as np
import pytest
import xarray as xr

from lagice.errors import ConfigError
from lagice.scenes.builder import finish
from lagice.scenes.hooks.wind_square import turning_wind, wind_components

from helpers import scene_sim

KW = {"domain.resolution_m": 50e3, "forcing.wind.params.ramp_h": 1.0, "forcing.wind.params.turn_h": 3.0,
      "run.seed": 3}
CENTER = np.array([250e3, 250e3])


@pytest.fixture(autouse=True)
def one_thread():
    """Tiny meshes: one numba thread (parallel fork/join dominates otherwise)."""
    import numba

    n = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(n)


def test_rotating_scene_rotates_answer(tmp_path):
    """Mesh, wind and boundary rotated by 90° about the centre (same triangles, same
    cohesion): the explicit solution is the rotated one to round-off."""
    a = scene_sim("wind_square", tmp_path / "a", {**KW, "run.duration": "8h"})
    b = scene_sim("wind_square", tmp_path / "b", {**KW, "run.duration": "8h", "domain.rotate_deg": 90.0,
                                                  "forcing.wind.params.dir0_deg": 90.0})
    ma, mb = a.model, b.model
    assert np.array_equal(ma.mesh.triangles, mb.mesh.triangles)
    assert np.array_equal(ma.state.cohesion, mb.state.cohesion)
    a.run()
    b.run()
    assert ma.state.damage.max() > 0.1, "the test should include damage"
    R = np.array([[0.0, -1.0], [1.0, 0.0]])
    ua, ub = ma.state.velocity, mb.state.velocity
    scale = np.abs(ua).max()
    assert scale > 1e-3
    assert np.abs(ub - ua @ R.T).max() < 1e-9 * scale
    ta, tb = ma.transport_velocity, mb.transport_velocity
    assert np.abs(tb - ta @ R.T).max() < 1e-9 * scale
    xa = (ma.mesh.nodes - CENTER) @ R.T + CENTER
    assert np.abs(mb.mesh.nodes - xa).max() < 1e-6  # metres
    assert np.abs(mb.state.damage - ma.state.damage).max() < 1e-9
    # stress rotates as a tensor: σ' = R σ Rᵀ -> (σyy, σxx, −σxy)
    sa, sb = ma.state.stress, mb.state.stress
    assert np.abs(sb - np.c_[sa[:, 1], sa[:, 0], -sa[:, 2]]).max() < 1e-9 * np.abs(sa).max()


def test_run_writes_outputs(tmp_path):
    sim = scene_sim("wind_square", tmp_path, {**KW, "run.duration": "6h", "output.plot": True,
                                              "output.every": "3h"})
    res = finish(sim)
    assert res["png"].exists() and res["png"].stat().st_size > 10_000
    ts = xr.load_dataset(tmp_path / "timeseries.nc", decode_times=False)
    assert ts.sizes["time"] == 37  # the start and 36 steps of 10 min
    vol = ts["ice_volume"].values
    assert np.abs(vol / vol[0] - 1).max() < 1e-9  # Lagrangian mass bookkeeping, closed basin
    assert 0 <= ts["mean_damage"].values[-1] < 1 and np.all(ts["substeps"].values[1:] >= 1)
    snaps = sorted((tmp_path / "snapshots").glob("snapshot_*.nc"))
    assert len(snaps) == 3
    ds = xr.load_dataset(snaps[-1])
    assert ds["mesh"].attrs["cf_role"] == "mesh_topology"
    assert ds["damage"].dims == ("time", "mesh_face") and ds["velocity_x"].dims == ("time", "mesh_node")
    assert np.all(np.isfinite(ds["velocity_x"].values)) and np.all(ds["total_deformation_rate"].values >= 0)
    # coast nodes stay put
    m = sim.model
    coast = m.mesh.coast_nodes()
    assert np.abs(m.state.velocity[coast]).max() == 0.0


def test_wind_schedule():
    kw = dict(speed_m_s=20.0, ramp_h=6.0, turn_h=24.0, turn_deg=90.0)
    assert wind_components(0.0, **kw) == (0.0, 0.0)
    assert wind_components(3 * 3600, **kw) == pytest.approx((10.0, 0.0))
    assert wind_components(6 * 3600, **kw) == pytest.approx((20.0, 0.0))
    u, v = wind_components(18 * 3600, **kw)
    assert math.degrees(math.atan2(v, u)) == pytest.approx(45.0) and math.hypot(u, v) == pytest.approx(20)
    assert wind_components(40 * 3600, **kw) == pytest.approx((0.0, 20.0), abs=1e-12)
    x = np.zeros(4)
    assert np.shape(turning_wind(0.0, x, x, **kw)[0]) == (4,)


@pytest.mark.parametrize("ov,match", [
    ({"domain.resolution_m": -1}, "resolution_m"), ({"solver.name": "magic"}, "solver.name"),
    ({"forcing.wind.params.spead_m_s": 3}, "spead_m_s"), ({"solver.dt": 0}, "solver.dt"),
    ({"forcing.wind.function": "lagice.nowhere:wind"}, "forcing.wind.function"),
])
def test_bad_input_fails_before_meshing(ov, match, monkeypatch, tmp_path):
    import lagice.scenes.builder as mod

    def no_mesh(*a, **k):
        raise AssertionError("meshing started before validation")

    monkeypatch.setattr(mod, "generate_mesh", no_mesh)
    with pytest.raises(ConfigError, match=match):
        scene_sim("wind_square", tmp_path, ov)
