"""Scene wind_square (issue 3): rotation invariance, outputs, wind schedule."""
import math

import numpy as np
import pytest
import xarray as xr

from lagice.errors import ConfigError
from lagice.scenes import SCENES, scene_module, wind_square

KW = dict(resolution_m=50e3, ramp_h=1.0, turn_h=3.0, seed=3)


@pytest.fixture(autouse=True)
def one_thread():
    """Tiny meshes: one numba thread (parallel fork/join dominates otherwise)."""
    import numba

    n = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(n)


def advance(sc, hours):
    for _ in range(int(round(hours * 3600 / sc.dt_s))):
        sc.solver.step(sc.state, sc.dt_s)
        wind_square.lagrangian_step(sc.mesh, sc.state, sc.solver, sc.dt_s)


def test_rotating_scene_rotates_answer():
    """Mesh nodes, wind and boundary rotated by 90° about the centre (same
    triangles, same cohesion): the explicit solution is the rotated one to round-off."""
    a = wind_square.build(**KW)
    b = wind_square.build(rotation_deg=90.0, **KW)
    assert np.array_equal(a.mesh.triangles, b.mesh.triangles)
    assert np.array_equal(a.state.cohesion, b.state.cohesion)
    advance(a, 8.0)
    advance(b, 8.0)
    assert a.state.damage.max() > 0.1, "the test should include damage"
    R = np.array([[0.0, -1.0], [1.0, 0.0]])
    ua, ub = a.state.velocity, b.state.velocity
    scale = np.abs(ua).max()
    assert scale > 1e-3
    assert np.abs(ub - ua @ R.T).max() < 1e-9 * scale
    xa = (a.mesh.nodes - a.center) @ R.T + a.center
    assert np.abs(b.mesh.nodes - xa).max() < 1e-6  # metres
    assert np.abs(b.state.damage - a.state.damage).max() < 1e-9
    # stress rotates as a tensor: σ' = R σ Rᵀ -> (σyy, σxx, −σxy)
    sa, sb = a.state.stress, b.state.stress
    assert np.abs(sb - np.c_[sa[:, 1], sa[:, 0], -sa[:, 2]]).max() < 1e-9 * np.abs(sa).max()


def test_run_writes_netcdf_and_png(tmp_path):
    res = wind_square.run(tmp_path, days=0.25, progress=False, **KW)
    assert set(res) >= {"netcdf", "png", "wall_s"}
    assert res["png"].exists() and res["png"].stat().st_size > 10_000
    ds = xr.load_dataset(res["netcdf"])
    assert ds["mesh"].attrs["cf_role"] == "mesh_topology"
    assert ds["damage"].dims == ("snapshot", "mesh_face")
    assert ds["u"].dims == ("snapshot", "mesh_node")
    assert ds.attrs["solver"] == "explicit"
    assert np.all(np.isfinite(ds["u"].values)) and np.all(ds["strain_rate_total"].values >= 0)
    # Lagrangian mass bookkeeping: volume conserved (no thermodynamics, closed basin)
    vol = ds["ice_volume"].values
    assert np.abs(vol / vol[0] - 1).max() < 1e-9
    assert 0 <= ds["mean_damage"].values[-1] < 1
    # coast nodes stay put
    st = res["scene"]
    coast = st.mesh.coast_nodes()
    assert np.abs(st.state.velocity[coast]).max() == 0.0


def test_wind_schedule():
    w = wind_square.UniformTurningWind(20.0, ramp_s=6 * 3600, turn_s=86400, turn_deg=90.0)
    assert w.components(0.0) == (0.0, 0.0)
    assert w.components(3 * 3600) == pytest.approx((10.0, 0.0))
    assert w.components(6 * 3600) == pytest.approx((20.0, 0.0))
    u, v = w.components(18 * 3600)
    assert math.degrees(math.atan2(v, u)) == pytest.approx(45.0) and math.hypot(u, v) == pytest.approx(20)
    assert w.components(40 * 3600) == pytest.approx((0.0, 20.0), abs=1e-12)
    x = np.zeros(4)
    assert np.shape(w(0.0, x, x)[0]) == (4,)


def test_registered_and_bad_input(monkeypatch):
    assert "wind_square" in SCENES and scene_module("wind_square") is wind_square

    def no_mesh(*a, **k):
        raise AssertionError("meshing started before validation")

    monkeypatch.setattr(wind_square, "generate_mesh", no_mesh)
    for kw, match in (({"resolution_m": -1}, "resolution_m"), ({"solver": "magic"}, "solver"),
                      ({"wind_speed": -3}, "wind_speed"), ({"dt_s": 0}, "dt_s"),
                      ({"resolution_m": 400e3}, "resolution_m")):
        with pytest.raises(ConfigError, match=match):
            wind_square.build(**kw)
