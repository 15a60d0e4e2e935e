"""The short winter_basin variant through the CLI, as a user runs it."""
import json
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

pytestmark = pytest.mark.slow

SHORT = ["domain.resolution_m=40e3", "run.duration=\"12h\"", "output.every=\"6h\"", "checkpoint.every=\"6h\"",
         "forcing.grid_spacing_m=50e3"]


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("wb")
    cmd = [sys.executable, "-m", "lagice.cli", "run", "winter_basin", "--out", str(out)]
    for s in SHORT:
        cmd += ["--set", s]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    return out, r


def test_cli_short_winter_basin_outputs(short_run):
    out, r = short_run
    assert "winter_basin.png" in r.stdout and "sim-days/wall-hour" in r.stdout
    index = json.loads((out / "snapshots" / "index.json").read_text())
    assert [e["time_s"] for e in index] == [0.0, 21600.0, 43200.0]
    xu = pytest.importorskip("xugrid")
    last = out / "snapshots" / index[-1]["file"]
    uds = xu.open_dataset(last)
    ds = xr.open_dataset(last)
    for name, units in (("thickness", "m"), ("concentration", "1"), ("damage", "1"), ("velocity_x", "m s-1"),
                        ("total_deformation_rate", "s-1"), ("stress_xy", "Pa")):
        assert ds[name].attrs["units"] == units, name
    assert uds.ugrid.grid.n_face == ds.sizes["mesh_face"]
    assert "3413" in ds["crs"].attrs["crs_wkt"] or "Polar" in ds["crs"].attrs["crs_wkt"]
    assert str(ds["time"].values[0]).startswith("2026-01-15T12")
    a = ds["concentration"].values
    d = ds["damage"].values
    assert np.all((a >= 0) & (a <= 1)) and np.all((d >= 0) & (d < 1))
    assert np.abs(ds["velocity_x"].values).max() > 1e-3, "the wind moves the ice"
    summary = json.loads((out / "summary.json").read_text())
    b = summary["volume_budget"]
    assert b["thermodynamic_m3"] > 0, "winter: ice grows"
    assert abs(b["relative_residual"]) < 1e-10, "volume budget closes"
    assert (out / "winter_basin.png").stat().st_size > 20_000


def test_cli_resume_is_bit_identical(short_run, tmp_path):
    """Copy the run, drop what came after the 6 h checkpoint, ``lagice resume``
    it: the final snapshot equals the uninterrupted run's bit for bit."""
    import shutil

    out, _ = short_run
    copy = tmp_path / "moved_run"
    shutil.copytree(out, copy)
    ck = sorted((copy / "checkpoints").glob("checkpoint_*.npz"))
    assert [int(p.stem.split("_")[1]) for p in ck] == [36, 72]
    ck[-1].unlink()
    (copy / "snapshots" / "snapshot_00000072.nc").unlink()
    r = subprocess.run([sys.executable, "-m", "lagice.cli", "info", str(ck[0])], capture_output=True, text=True)
    assert r.returncode == 0 and "winter_basin" in r.stdout
    r = subprocess.run([sys.executable, "-m", "lagice.cli", "resume", str(ck[0])], capture_output=True,
                       text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    assert str(copy) in r.stdout
    a = xr.load_dataset(out / "snapshots" / "snapshot_00000072.nc")
    b = xr.load_dataset(copy / "snapshots" / "snapshot_00000072.nc")
    for name in ("thickness", "concentration", "damage", "stress_xx", "velocity_x", "mesh_node_x"):
        assert np.array_equal(a[name].values, b[name].values), name
