"""The CLI as a user runs it: a real subprocess writing real files."""
import json
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "lagice.cli", *args], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


@pytest.mark.slow
def test_cli_run_compression(tmp_path):
    out = tmp_path / "run"
    r = run_cli("run", "uniaxial_compression", "--out", str(out), "--set", "domain.resolution_m=12500",
                "--set", "run.duration=10000s", "--set", "run.seed=3")
    assert r.returncode == 0, r.stderr
    assert "plot:" in r.stdout and "uniaxial_compression.png" in r.stdout
    # the mesh it made, against what was asked
    line = next(ln for ln in r.stdout.splitlines() if "mesh:" in ln)
    n_faces = xr.open_dataset(sorted((out / "snapshots").glob("*.nc"))[0]).sizes["mesh_face"]
    assert f"mesh: {n_faces} elements" in line and "x domain.resolution_m = 12.5 km" in line, line
    png = out / "uniaxial_compression.png"
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds = xr.load_dataset(out / "timeseries.nc", decode_times=False)
    cfg = json.loads(ds.attrs["lagice_config"])
    assert cfg["domain"]["resolution_m"] == 12500 and cfg["run"]["seed"] == 3
    strain = ds["macro_strain"].values
    assert strain[-1] == pytest.approx(5e-5, rel=1e-12)
    # elastic phase: macroscopic stress ~ -E0 * strain (E0 = 2 cs^2 (1 + nu) rho = 585 MPa)
    assert np.allclose(-ds["macro_stress"].values[-10:], 585e6 * strain[-10:], rtol=0.05)
    info = run_cli("info", str(out / "timeseries.nc"))
    assert info.returncode == 0 and "macro_stress" in info.stdout
    replot = run_cli("plot", str(out), "--png", str(tmp_path / "again.png"))
    assert replot.returncode == 0, replot.stderr
    assert (tmp_path / "again.png").stat().st_size > 10_000


def test_cli_bad_override_names_key(tmp_path):
    r = run_cli("run", "uniaxial_compression", "--out", str(tmp_path), "--set", "rheology.cohesion=3")
    assert r.returncode == 2
    assert "unknown key rheology.cohesion" in r.stderr
    r = run_cli("run", "uniaxial_compression", "--out", str(tmp_path), "--set", "cohesion=3")
    assert r.returncode == 2 and "expected table.key=value" in r.stderr
    r = run_cli("run", "no_such_scene")
    assert r.returncode == 2 and "unknown scene 'no_such_scene'" in r.stderr
    # the same key twice with different values: the first would be silently ignored
    r = run_cli("run", "uniaxial_compression", "--out", str(tmp_path), "--set", "run.seed=3", "--set", "run.seed=4")
    assert r.returncode == 2
    assert "--set run.seed is given twice (run.seed=3, then run.seed=4)" in r.stderr
    assert not any(tmp_path.iterdir())


def test_cli_scenes_lists_every_bundled_scene_with_a_description():
    from lagice.scenes.config import list_scenes

    r = run_cli("scenes")
    assert r.returncode == 0
    scenes = list_scenes()
    assert {"uniaxial_compression", "wind_square", "shear_channel", "winter_basin"} <= set(scenes)
    for name, (_path, desc) in scenes.items():
        assert name in r.stdout and desc and desc in r.stdout



def test_python_m_lagice_is_the_lagice_command(tmp_path):
    """``python -m lagice`` runs the same CLI as ``python -m lagice.cli`` (the same scene list,
    the same one-line error and exit status 2 for a bad key)."""
    a = subprocess.run([sys.executable, "-m", "lagice", "scenes"], capture_output=True, text=True, timeout=300)
    assert a.returncode == 0 and a.stdout == run_cli("scenes").stdout
    bad = subprocess.run([sys.executable, "-m", "lagice", "run", "uniaxial_compression", "--out", str(tmp_path / "r"),
                          "--set", "rheology.cohesion=3"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "rheology.cohesion" in bad.stderr

@pytest.mark.slow
def test_cli_diagnose_real_output(tmp_path):
    """``lagice diagnose`` on the snapshots of a real (moving-mesh) run writes
    diagnostics.json with the documented keys, and its invariants agree with
    the node displacements in the files."""
    import json

    from lagice.diagnostics.report import JSON_KEYS

    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", str(out), "--set", "run.duration=3000.0",
                "--set", "solver.dt=100.0", "--set", "output.every=1500.0",
                "--set", "domain.resolution_m=25e3", "--set", "lagrangian.enabled=true",
                "--set", 'boundary.top.u="2.0*minimum(1.0, t/600.0)"', "--set", "output.plot=false")
    assert r.returncode == 0, r.stderr
    d = run_cli("diagnose", str(out))
    assert d.returncode == 0, d.stderr
    res = json.loads((out / "diagnostics" / "diagnostics.json").read_text())
    for key in ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
                "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s"):
        assert key in res and key in JSON_KEYS
    assert set(res) <= set(JSON_KEYS)
    assert res["dt_s"] == 1500.0
    assert res["mean_shear_s"] > 0 and 0 < res["localisation_half_shear_area_fraction"] <= 0.5
    assert any(p.suffix == ".png" for p in (out / "diagnostics").iterdir())
    # away from the boundary: only the elements >= 40 km from the edge of the 200 km box
    d2 = run_cli("diagnose", str(out), "--coast-buffer-km", "40", "--out", str(tmp_path / "diag40"))
    assert d2.returncode == 0, d2.stderr
    res40 = json.loads((tmp_path / "diag40" / "diagnostics.json").read_text())
    idx = json.loads((out / "snapshots" / "index.json").read_text())
    ds0 = xr.load_dataset(out / "snapshots" / idx[-2]["file"])
    xy = np.column_stack([ds0["mesh_node_x"].values, ds0["mesh_node_y"].values])
    c = xy[ds0["mesh_face_nodes"].values].mean(axis=1)
    tri = ds0["mesh_face_nodes"].values
    e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    u, n = np.unique(e, axis=0, return_counts=True)
    a, b = xy[u[n == 1, 0]], xy[u[n == 1, 1]]  # boundary segments (edges of one triangle)
    ab = b - a  # brute-force point-segment distance, every centroid to every boundary edge
    t = np.clip(np.einsum("pkd,kd->pk", c[:, None, :] - a[None], ab) / np.einsum("kd,kd->k", ab, ab), 0, 1)
    dist = np.linalg.norm(c[:, None, :] - (a[None] + t[..., None] * ab[None]), axis=2).min(axis=1)
    assert res40["n_elements"] == int(np.sum(dist >= 40e3)) < res["n_elements"]
    bad = run_cli("diagnose", str(out), "--coast-buffer-km", "500")
    assert bad.returncode == 2 and "use a smaller buffer" in bad.stderr


def test_plot_and_diagnose_beside_a_run_that_is_still_going(tmp_path):
    """``lagice plot`` and ``lagice diagnose`` only read a run folder: beside a process that
    holds its lock (here a real holder process of ``lagice.rundir.RunLock``, the lock a run
    holds while it runs) they work on the snapshots written so far, say that the run is
    still going (naming its pid), and write their files whole (through a temporary file and
    a rename: none is left behind). Once the holder is gone they say nothing of it."""
    out = tmp_path / "run"
    r = run_cli("run", "shear_box", "--out", str(out), "--set", "run.duration=3000.0",
                "--set", "solver.dt=100.0", "--set", "output.every=1500.0",
                "--set", "domain.resolution_m=25e3", "--set", "lagrangian.enabled=true",
                "--set", 'boundary.top.u="2.0*minimum(1.0, t/600.0)"')
    assert r.returncode == 0, r.stderr
    holder = subprocess.Popen([sys.executable, "-c", "import sys; from lagice.rundir import RunLock; "
                               "RunLock(sys.argv[1]).acquire(); print('held', flush=True); sys.stdin.read()",
                               str(out)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        p = run_cli("plot", str(out))
        assert p.returncode == 0, p.stderr
        assert "still going" in p.stdout and f"pid {holder.pid}" in p.stdout and "day 0.035" in p.stdout
        png = out / "shear_box.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
        before = png.read_bytes()
        other = run_cli("plot", str(out), "--png", str(tmp_path / "elsewhere.png"))
        assert other.returncode == 0, other.stderr
        assert (tmp_path / "elsewhere.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.exists() and png.read_bytes() == before  # --png leaves the run's own figure in place
        d = run_cli("diagnose", str(out))
        assert d.returncode == 0, d.stderr
        assert "still going" in d.stdout and f"pid {holder.pid}" in d.stdout
        assert json.loads((out / "diagnostics" / "diagnostics.json").read_text())["dt_s"] == 1500.0
        assert not [q for q in out.rglob("*") if ".tmp" in q.name]
    finally:
        holder.stdin.close()
        holder.wait(timeout=60)
    again = run_cli("plot", str(out))
    assert again.returncode == 0, again.stderr
    assert "still going" not in again.stdout
