"""The CLI as a user runs it: a real subprocess writing real files."""
import subprocess
import sys

import numpy as np
import xarray as xr


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "lagice.cli", *args], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


def test_cli_run_compression(tmp_path):
    out = tmp_path / "run"
    r = run_cli("run", "uniaxial_compression", "--out", str(out), "--set", "n_across=8",
                "--set", "max_strain=5e-5", "--set", "seed=3")
    assert r.returncode == 0, r.stderr
    assert "plot:" in r.stdout and "compression.png" in r.stdout
    png = out / "compression.png"
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ds = xr.load_dataset(out / "compression.nc")
    assert ds.attrs["n_across"] == 8 and ds.attrs["seed"] == 3
    strain = ds["macro_strain"].values
    assert strain[-1] >= 5e-5 - 1e-12
    # elastic phase: macroscopic stress ~ -E0 * strain
    assert np.allclose(-ds["macro_stress"].values[-10:], ds.attrs["young_modulus_pa"] * strain[-10:], rtol=0.05)
    info = run_cli("info", str(out / "compression.nc"))
    assert info.returncode == 0 and "macro_stress" in info.stdout


def test_cli_bad_override_names_key(tmp_path):
    r = run_cli("run", "uniaxial_compression", "--out", str(tmp_path), "--set", "cohesion=3")
    assert r.returncode == 2
    assert "--set cohesion: unknown key" in r.stderr
    r = run_cli("run", "no_such_scene")
    assert r.returncode == 2 and "unknown scene 'no_such_scene'" in r.stderr
    assert not any(tmp_path.iterdir())


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
