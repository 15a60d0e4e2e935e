"""Snapshot output as users read it: xarray/xugrid, units, CRS, gridded and VTU."""
import json

import meshio
import numpy as np
import pytest
import xarray as xr

from lagice.io.gridded import conservative_grid_average
from lagice.mesh import generate_mesh, rectangle_domain
from lagice.scenes.builder import build_simulation
from lagice.scenes.config import load_scene

FAST = {"run.duration": 800.0, "solver.dt": 40.0, "output.every": 400.0, "domain.resolution_m": 25e3,
        "run.progress": False, "output.plot": False, "boundary.top.u": "5e-2*minimum(1.0, t/600.0)",
        "output.grid_resolution_m": 30e3, "output.vtu": True}


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("out")
    sim = build_simulation(load_scene("shear_box", FAST), d)
    sim.run()
    return d, sim


def test_snapshots_follow_ugrid_cf(run_dir):
    d, sim = run_dir
    index = json.loads((d / "snapshots" / "index.json").read_text())
    assert [e["step"] for e in index] == [0, 10, 20]
    ds = xr.open_dataset(d / "snapshots" / index[-1]["file"])
    assert ds["mesh"].attrs["cf_role"] == "mesh_topology"
    assert ds["thickness"].attrs["units"] == "m"
    assert ds["thickness"].attrs["standard_name"] == "sea_ice_thickness"
    assert ds["concentration"].attrs["standard_name"] == "sea_ice_area_fraction"
    assert ds["velocity_x"].attrs["units"] == "m s-1"
    assert ds["total_deformation_rate"].attrs["units"] == "s-1"
    assert "_FillValue" not in ds["damage"].encoding or ds["damage"].encoding["_FillValue"] is None
    assert "polar_stereographic" in ds["crs"].attrs.get("grid_mapping_name", "")
    assert np.array_equal(ds["damage"].values[0], sim.model.state.damage)
    for k, comp in enumerate(("xx", "yy", "xy")):
        assert np.array_equal(ds[f"stress_{comp}"].values[0], sim.model.state.stress[:, k])
        assert ds[f"stress_{comp}"].attrs["units"] == "Pa"
    # the snapshot's velocity is the transport velocity (the one that moved the nodes)
    assert np.array_equal(ds["velocity_x"].values[0], sim.model.transport_velocity[:, 0])
    assert ds.attrs["Conventions"] == "CF-1.8 UGRID-1.0" and ds.attrs["lagice_version"]
    assert json.loads(ds.attrs["lagice_config"])["scene"]["name"] == "shear_box"
    xu = pytest.importorskip("xugrid")
    uds = xu.open_dataset(d / "snapshots" / index[-1]["file"])
    assert uds.ugrid.grid.n_face == sim.model.mesh.n_elements


def test_gridded_output_conserves_totals(run_dir):
    d, sim = run_dir
    g = xr.open_dataset(d / "snapshots" / "grid_00000020.nc")
    cell = 30e3 * 30e3
    vol_grid = float(np.nansum(g["thickness"].values * g["coverage"].values) * cell)
    assert vol_grid == pytest.approx(sim.model.state.ice_volume_m3, rel=1e-12)
    assert g["thickness"].attrs["grid_mapping"] == "crs"
    m = meshio.read(d / "snapshots" / "snapshot_00000020.vtu")
    assert np.allclose(m.cell_data["damage"][0], sim.model.state.damage)
    assert np.allclose(m.cell_data["stress"][0], sim.model.state.stress)
    assert set(m.cell_data) >= {"thickness", "concentration", "cohesion", "total_deformation_rate"}
    assert np.allclose(m.point_data["velocity"][:, :2], sim.model.transport_velocity)
    pvd = (d / "snapshots" / "snapshots.pvd").read_text()
    assert pvd.count("<DataSet") == 3 and 'timestep="800.0"' in pvd


def test_conservative_average_exact_on_linear_rotation():
    poly, _ = rectangle_domain(90e3, 60e3)
    mesh = generate_mesh(poly, 9e3)
    v = np.random.default_rng(1).random(mesh.n_elements)
    xe = np.linspace(-10e3, 100e3, 8)
    ye = np.linspace(-10e3, 70e3, 6)
    out, cov = conservative_grid_average(mesh.nodes, mesh.triangles, {"v": v}, xe, ye)
    cell = np.outer(np.diff(ye), np.diff(xe))
    assert np.nansum(out["v"] * cov * cell) == pytest.approx(np.sum(v * mesh.areas()), rel=1e-12)
    assert np.all((cov >= 0) & (cov <= 1 + 1e-12))
    assert np.isnan(out["v"][cov == 0]).all()
